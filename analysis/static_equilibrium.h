#pragma once
// Independent static check: Newton's method on the same Neo-Hookean energy, assembled
// with Eigen and solved by sparse Cholesky (LDLT), for a gravity-loaded body with fixed
// nodes. The explicit solver run to rest with damping (dynamic relaxation) must reach the
// same state.
#include <cstdint>
#include <vector>

#include "sim/mesh/tet_mesh.h"

namespace softtled {

struct StaticResult {
  std::vector<double> u;  // 3 x nnode SoA, equilibrium displacement [m]
  int newton_iterations = 0;
  double residual = 0;    // final |f_int - f_ext|_inf over free DOFs [N]
};

// fixed: nnode flags (non-zero = fixed). Load steps ramp gravity for robustness.
StaticResult solve_static_equilibrium(const TetMesh& m, double E, double nu, double rho, const double g[3],
                                      const std::vector<std::uint8_t>& fixed, int element = 0, int load_steps = 4);

}  // namespace softtled
