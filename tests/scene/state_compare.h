#pragma once
// Two runs' displacements compared (backends, execution modes, obstacle shapes), and the
// nodes' smallest distance to something.
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

// Smallest dist(x) over every node's current position x [m] (e.g. a signed distance).
template <class F>
double min_node_distance(Simulation& sim, F dist) {
  const HostState& st = sim.state();
  const int n = sim.mesh().nnode();
  double g = 1e300;
  for (int i = 0; i < n; ++i) {
    const double x[3] = {sim.mesh().X[3 * i] + st.u[i], sim.mesh().X[3 * i + 1] + st.u[n + i],
                         sim.mesh().X[3 * i + 2] + st.u[2 * n + i]};
    g = std::min(g, dist(x));
  }
  return g;
}

}  // namespace softtled::test
