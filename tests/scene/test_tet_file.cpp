// body.shape = "tet_file": a Gmsh mesh read as it is runs like a meshed body. The puck
// (assets/scenes/puck_drop.toml) dropped onto the floor lands, never sinks into it and
// comes to rest, settled by its own weight. On the CPU backend.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene_helpers.h"
#include "sim/mesh/tet_io.h"
#include "sim/scene/simulation.h"

using namespace softtled;

namespace {

double kinetic_energy(Simulation& sim) {
  const HostState& st = sim.state();
  const int n = sim.mesh().nnode();
  const double dt = sim.time_step().dt;
  double ke = 0;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) ke += 0.5 * sim.lumped_mass()[i] * std::pow(st.du[k * n + i] / dt, 2);
  return ke;
}

}  // namespace

TEST(TetFile, GmshPuckDropsAndComesToRestOnTheFloor) {
  Simulation sim(load_scene(test::assets_dir() + "/scenes/puck_drop.toml"), "cpu");
  // The mesh is the file's (no TetGen): every node and tet of the Gmsh mesh.
  const TetMesh file = load_tet_mesh(test::assets_dir() + "/meshes/puck.msh");
  ASSERT_EQ(sim.mesh().nnode(), file.nnode());
  ASSERT_EQ(sim.mesh().ntet(), file.ntet());
  const double floor_y = -4e-3, h = 4e-3;
  const int n = sim.mesh().nnode();
  double ke_max = 0, lowest = INFINITY, landed_at = -1;
  const long every = std::max(1L, std::lround(0.002 / sim.time_step().dt));
  while (sim.time() < 0.3) {
    sim.advance(every, every);
    const HostState& st = sim.state();
    double y_min = INFINITY;
    for (int i = 0; i < n; ++i) y_min = std::min(y_min, sim.mesh().X[3 * i + 1] + st.u[n + i]);
    lowest = std::min(lowest, y_min);
    if (landed_at < 0 && y_min < floor_y + 1e-9) landed_at = sim.time();
    ke_max = std::max(ke_max, kinetic_energy(sim));
  }
  // Free fall of 2 mm: sqrt(2 h / g) = 20 ms (damping alpha = 20 slows it a little).
  EXPECT_GT(landed_at, 0.018);
  EXPECT_LT(landed_at, 0.030);
  EXPECT_GE(lowest, floor_y - 1e-9) << "a node sank into the floor";
  const double ke_end = kinetic_energy(sim);
  EXPECT_LT(ke_end, 1e-3 * ke_max) << "kinetic energy " << ke_end << " J at 0.3 s, peak " << ke_max << " J";
  // At rest on the floor: the centroid h/2 above it, less the settlement under its own
  // weight (uniaxial, frictionless floor: rho g h^2 / (3 E) for the mass centre).
  const HostState& st = sim.state();
  double M = 0, cy = 0;
  for (int i = 0; i < n; ++i) {
    M += sim.lumped_mass()[i];
    cy += sim.lumped_mass()[i] * (sim.mesh().X[3 * i + 1] + st.u[n + i]);
  }
  cy /= M;
  const double settle = 1000 * 9.81 * h * h / (3 * 3000);
  EXPECT_NEAR(floor_y + h / 2 - cy, settle, 0.2 * settle);
}
