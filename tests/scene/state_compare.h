#pragma once
// Two runs' displacements compared (backends, execution modes, obstacle shapes).
#include <algorithm>
#include <cmath>

#include "sim/scene/simulation.h"

namespace softtled::test {

// Largest |u_a - u_b| over every node and component [m].
inline double max_abs_diff(Simulation& a, Simulation& b) {
  const HostState &sa = a.state(), &sb = b.state();
  double w = 0;
  for (std::size_t j = 0; j < sa.u.size(); ++j) w = std::max(w, std::fabs(sa.u[j] - sb.u[j]));
  return w;
}

// Largest |u| component [m] (the scale a difference is compared with).
inline double max_abs_u(Simulation& a) {
  double w = 0;
  for (double v : a.state().u) w = std::max(w, std::fabs(v));
  return w;
}

}  // namespace softtled::test
