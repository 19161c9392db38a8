// The paper's scene (section IV): the upright torus falls 2 mm onto the floor.
// Asserts the free-fall time to first contact, non-penetration, the first compression
// and rebound, and, over a longer run, that the ring tips over and comes to rest
// (../shared/physics-notes.md s.3: the upright state is unstable even without friction).
// And the fall itself: damped free fall from a moving start converges at second order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "backends.h"
#include "scene_helpers.h"
#include "sim/scene/simulation.h"

using namespace softtled;
using namespace softtled::test;

namespace {

double node_extent(Simulation& sim, int axis) {
  const HostState& st = sim.state();
  const int n = sim.mesh().nnode();
  double lo = 1e300, hi = -1e300;
  for (int i = 0; i < n; ++i) {
    const double x = sim.mesh().X[3 * i + axis] + st.u[axis * n + i];
    lo = std::min(lo, x), hi = std::max(hi, x);
  }
  return hi - lo;
}
}  // namespace

class TorusDrop : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(TorusDrop);

TEST_P(TorusDrop, FirstContactCompressionAndRebound) {
  Scene s = load_scene(assets_dir() + "/scenes/torus_drop.toml");
  Simulation sim(s, backend());
  EXPECT_GT(sim.mesh().ntet(), 6000);
  const double dt = sim.time_step().dt;
  const Diagnostics d0 = sim.diagnostics();
  const double gap0 = d0.min_gap;
  // Analytic damped free-fall time to close the initial gap, by bisection.
  double lo = 0, hi = 0.1;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (damped_fall(9.81, 10, mid) > gap0 ? hi : lo) = mid;
  }
  const double t_fall = 0.5 * (lo + hi);
  const long every = std::lround(2.5e-4 / dt);
  double t_contact = -1, y_contact = 0, y_min = 1e9, t_min = 0, min_gap = 1e9, ux_at_min = 0;
  Diagnostics d;
  while (sim.time() < 0.08) {
    sim.step(every);
    d = sim.diagnostics();
    min_gap = std::min(min_gap, d.min_gap);
    if (t_contact < 0 && d.n_contact > 0) t_contact = d.t, y_contact = d.centroid[1];
    if (t_contact > 0 && d.centroid[1] < y_min) y_min = d.centroid[1], t_min = d.t, ux_at_min = d.tracked[0];
  }
  EXPECT_NEAR(t_contact, t_fall, 5e-4) << "first contact vs analytic damped free fall";
  EXPECT_GT(min_gap, -1e-9) << "a node went below the floor";
  EXPECT_GT(y_contact - y_min, 1e-3) << "the torus must compress by more than 1 mm (E = 3 kPa)";
  EXPECT_GT(t_min, t_contact + 0.01);
  EXPECT_GT(ux_at_min, 0.0) << "the outer equator node (+x) moves outward while the ring is squashed";
  EXPECT_GT(d.centroid[1], y_min + 1e-3) << "it must rebound by 0.08 s";
  EXPECT_GT(node_extent(sim, 1), 15e-3) << "still standing at 0.08 s (it tips later)";
}

TEST_P(TorusDrop, RingTipsOverAndComesToRest) {
  // The coarse torus (45 x 9 surface grid) shows the same tipping at a fifth of the cost.
  Scene s = load_scene(assets_dir() + "/scenes/torus_drop.toml", {"body.segments=[45, 9]", "time.lambda=0.8"});
  Simulation sim(s, backend());
  EXPECT_GT(node_extent(sim, 1), 19e-3);  // upright: 20 mm tall
  double max_ke = 0;
  const long every = std::lround(5e-3 / sim.time_step().dt);
  while (sim.time() < 0.6) {
    sim.step(every);
    const Diagnostics d = sim.diagnostics();
    max_ke = std::max(max_ke, d.ke);
    ASSERT_TRUE(std::isfinite(d.ke));
    ASSERT_GT(d.min_gap, -1e-9);
  }
  const Diagnostics d = sim.diagnostics();
  EXPECT_LT(node_extent(sim, 1), 8e-3) << "after 0.6 s the ring lies flat: its height is about the tube diameter";
  EXPECT_NEAR(d.centroid[1], -12e-3 + 2.5e-3, 1e-3) << "centroid one tube radius above the floor";
  EXPECT_LT(d.ke, 0.01 * max_ke) << "kinetic energy decays toward rest";
}

class FreeFall : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(FreeFall);

TEST_P(FreeFall, SecondOrderInDtFromAMovingStart) {
  // Damped free fall (alpha = 10/s) from v0 = (0.1, 0.2, 0) m/s: every node moves alike, so
  // the centroid follows x(t) = v0 (1 - e^-at) / a + g/a (t - (1 - e^-at) / a). The central
  // difference is second order, and so must be its start: halving dt quarters the error.
  const double alpha = 10, g = 9.81, v0[3] = {0.1, 0.2, 0}, T = 0.015;
  double err[3];
  const double dts[3] = {1e-4, 5e-5, 2.5e-5};
  for (int l = 0; l < 3; ++l) {
    Scene s = box_scene("[time]\ndt = " + std::to_string(dts[l]) + "\n");
    s.velocity = {v0[0], v0[1], v0[2]};
    Simulation sim(s, backend());
    ASSERT_EQ(sim.time_step().dt, dts[l]);
    const Diagnostics d0 = sim.diagnostics();
    sim.advance(std::lround(T / dts[l]), 1000000);
    const Diagnostics d = sim.diagnostics();
    const double t = sim.time(), decay = (1 - std::exp(-alpha * t)) / alpha;
    double e2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double exact = v0[k] * decay + (k == 1 ? -g / alpha * (t - decay) : 0.0);
      e2 += std::pow(d.centroid[k] - d0.centroid[k] - exact, 2);
    }
    err[l] = std::sqrt(e2);
    std::printf("dt = %g s: centroid error %.3g m at t = %g s\n", dts[l], err[l], t);
  }
  EXPECT_GT(err[0] / err[1], 3.5) << "second order: halving dt quarters the error";
  EXPECT_GT(err[1] / err[2], 3.5);
}
