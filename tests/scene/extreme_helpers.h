#pragma once
// Scenes and state checks shared by the extremes tests at a fixed step (test_extremes.cpp)
// and with the adaptive step (test_adaptive_step.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "sim/fem/mesh_kinematics.h"
#include "sim/scene/simulation.h"

namespace softtled::test {

// A 10 mm box of 2x2x2 cells whose bottom is `gap` mm above a floor at y = -5 - gap.
inline Scene box_on_floor(const std::string& extra, double gap = 1.0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "[floor]\nenabled = true\npoint = [0, %.12g, 0]\n", -5.0 - gap);
  return parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\n" +
                         std::string(buf) + extra,
                     "extreme");
}

// Finite state, no node behind a plane, finite energies.
inline void expect_sane(Simulation& sim, const std::string& what) {
  for (double v : sim.state().u) ASSERT_TRUE(std::isfinite(v)) << what;
  const Diagnostics d = sim.diagnostics();
  EXPECT_GT(d.min_gap, -1e-9) << what << ": a node is below a plane";
  EXPECT_TRUE(std::isfinite(d.ke) && std::isfinite(d.se)) << what;
}

// Smallest volume ratio J over the elements now (mesh_element_J: the one definition).
inline double min_J(Simulation& sim) {
  const HostState& st = sim.state();
  const TetMesh& m = sim.mesh();
  double jmin = 1e300;
  for (int e = 0; e < m.ntet(); ++e) jmin = std::min(jmin, mesh_element_J(m, st.u, e));
  return jmin;
}

}  // namespace softtled::test
