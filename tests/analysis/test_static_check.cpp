#define _USE_MATH_DEFINES
// Independent static check (Eigen, Newton on the same Neo-Hookean energy) against the
// explicit solver run to rest with damping (dynamic relaxation), and the cantilever's
// first natural frequency against beam theory.
#include <gtest/gtest.h>

#include <cmath>

#include "scene_helpers.h"
#include "sim/scene/simulation.h"
#include "analysis/static_equilibrium.h"

using namespace softtled;
using namespace softtled::test;

namespace {
Scene beam(const std::vector<std::string>& extra) {
  std::vector<std::string> set = {"mesh.max_volume=2.0", "time.lambda=0.9"};
  set.insert(set.end(), extra.begin(), extra.end());
  return load_scene(assets_dir() + "/scenes/beam_cantilever.toml", set);
}

void compare_with_dynamic_relaxation(const std::string& element, const std::string& nu) {
  Simulation sim(beam({"material.element=" + element, "material.nu=" + nu}));
  const TetMesh& m = sim.mesh();
  const int n = m.nnode();
  std::vector<std::uint8_t> fixed(n, 0);
  for (int i = 0; i < n; ++i) fixed[i] = m.X[3 * i] < -20e-3 + 1e-9;
  const double g[3] = {0, -9.81, 0};
  const StaticResult st = solve_static_equilibrium(m, sim.params().E, sim.params().nu, sim.scene().rho, g, fixed,
                                                   element == "T4ANP" ? 1 : 0);
  EXPECT_LT(st.newton_iterations, 30);
  sim.advance(std::lround(0.15 / sim.time_step().dt), 1000);
  HostState dr = sim.state();
  double umax = 0, dmax = 0;
  for (int j = 0; j < 3 * n; ++j) {
    umax = std::max(umax, std::fabs(st.u[j]));
    dmax = std::max(dmax, std::fabs(st.u[j] - dr.u[j]));
  }
  EXPECT_GT(umax, 1e-4);
  EXPECT_LT(dmax, 1e-3 * umax) << element << ": dynamic relaxation vs Newton, max nodal difference " << dmax << " m of "
                               << umax << " m";
  std::printf("[static check %s nu=%s] Newton %d iterations; max |u_DR - u_Newton| = %.3g m (%.2g of max |u| = %.4g m)\n",
              element.c_str(), nu.c_str(), st.newton_iterations, dmax, dmax / umax, umax);
}
}  // namespace

TEST(StaticCheck, DynamicRelaxationMatchesNewtonT4) { compare_with_dynamic_relaxation("T4", "0.3"); }

TEST(StaticCheck, CantileverFirstFrequencyNearBeamTheory) {
  // Release the beam from its static sag with no gravity and no damping; the tip swings
  // at the first bending frequency f1 = 1.875^2 / (2 pi) sqrt(E I / (rho A L^4)).
  const double E = 1e6, rho = 1000, h = 4e-3, L = 40e-3;
  const double f1 = 1.875 * 1.875 / (2 * M_PI) * std::sqrt(E * (h * h * h * h / 12) / (rho * h * h * std::pow(L, 4)));
  double f_fe[2];
  for (int level = 0; level < 2; ++level) {
    Simulation sim(beam({level == 0 ? "mesh.max_volume=2.0" : "mesh.max_volume=0.5", "damping.alpha=0", "gravity.g=[0, 0, 0]"}));
    const TetMesh& m = sim.mesh();
    const int n = m.nnode();
    std::vector<std::uint8_t> fixed(n, 0);
    for (int i = 0; i < n; ++i) fixed[i] = m.X[3 * i] < -20e-3 + 1e-9;
    const double g[3] = {0, -9.81, 0};
    HostState s = sim.state();
    s.u = solve_static_equilibrium(m, E, 0.3, rho, g, fixed).u;
    sim.set_state(s);
    const int tip = sim.tracked_nodes()[0];
    // Period from successive upward zero crossings of the tip's vertical displacement.
    double prev = s.u[n + tip], t_first = -1, t_last = -1;
    int crossings = 0;
    HostState st;
    while (sim.time() < 0.16) {
      sim.advance(5, 1000000);
      st = sim.state();
      const double y = st.u[n + tip];
      if (prev < 0 && y >= 0) {  // upward zero crossing (linear interpolation)
        const double tc = sim.time() - 5 * sim.time_step().dt * y / (y - prev);
        if (t_first < 0) t_first = tc;
        t_last = tc;
        ++crossings;
      }
      prev = y;
    }
    ASSERT_GE(crossings, 2);
    f_fe[level] = (crossings - 1) / (t_last - t_first);
  }
  std::printf("[cantilever] f1 beam theory %.3f Hz; T4 coarse %.3f Hz, fine %.3f Hz\n", f1, f_fe[0], f_fe[1]);
  EXPECT_GT(f_fe[0], f_fe[1]) << "refinement softens linear tets";
  EXPECT_NEAR(f_fe[1], f1, 0.15 * f1);
}
