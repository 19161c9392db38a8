#include "sim/solver/host_forces.h"

#include "sim/fem/anp.h"
#include "sim/fem/central_difference.h"
#include "sim/solver/solver.h"
#include "sim/fem/tet_forces.h"

namespace softtled {

void host_internal_forces(const RestArrays<double>& r, const NeoHookean<double>& mat, int element,
                          const std::vector<double>& u, std::vector<double>& f) {
  const TetMeshView<double> v = r.view();
  const int ne = r.ntet, n = r.nnode;
  std::vector<double> fc(12 * ne);
  if (element == kT4ANP) {
    std::vector<double> vol(ne), p(n);
    for (int e = 0; e < ne; ++e) anp_element_volume(v, u.data(), vol.data(), e);
    for (int i = 0; i < n; ++i) anp_node_pressure(v, mat, vol.data(), p.data(), i);
    for (int e = 0; e < ne; ++e) anp_corner_forces(v, mat, u.data(), p.data(), fc.data(), e);
  } else {
    for (int e = 0; e < ne; ++e) tet_corner_forces(v, mat, u.data(), fc.data(), e);
  }
  f.resize(3 * n);
  for (int i = 0; i < n; ++i) {
    double fi[3];
    gather_node_force(v, fc.data(), i, fi);
    for (int k = 0; k < 3; ++k) f[k * n + i] = fi[k];
  }
}

}  // namespace softtled
