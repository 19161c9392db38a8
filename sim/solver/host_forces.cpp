#include "sim/solver/host_forces.h"

#include <stdexcept>

#include "sim/fem/central_difference.h"
#include "sim/solver/cpu_step.h"

namespace softtled {

void host_internal_forces(const RestArrays<double>& r, const NeoHookean<double>& mat, int element,
                          const std::vector<double>& u, std::vector<double>& f,
                          const std::vector<ElementLaw<double>>& laws) {
  TetMeshView<double> v = r.view();
  if (v.tet_law && laws.empty()) throw std::invalid_argument("host_internal_forces: the mesh has per-body laws");
  v.laws = laws.empty() ? nullptr : laws.data();
  const int ne = r.ntet, n = r.nnode;
  std::vector<double> fc(12 * ne), vol(element == kT4ANP ? ne : 0), p(element == kT4ANP ? n : 0);
  // Serial: called outside any parallel region, the stage's orphaned loops run on this thread.
  cpu_element_stage(v, mat, element, u.data(), AnpScratch<double>{vol.data(), p.data()}, fc.data());
  f.resize(3 * n);
  for (int i = 0; i < n; ++i) {
    double fi[3];
    gather_node_force(v.gather_start, v.gather_slot, fc.data(), i, fi);
    for (int k = 0; k < 3; ++k) f[k * n + i] = fi[k];
  }
}

}  // namespace softtled
