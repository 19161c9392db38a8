// Live changes (the viewer's panel, the Python module's set_params) against what a run
// started with the same values does, or against the physics: a change must act at once
// and leave everything else as it was, and a rollback or reset must treat the changed
// state consistently.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "scene_helpers.h"
#include "sim/core/input_error.h"
#include "sim/scene/plane_motion.h"
#include "sim/scene/simulation.h"
#include "sim/scene/watchdog.h"

using namespace softtled;
using namespace softtled::test;

namespace {

Scene torus(const std::vector<std::string>& set = {}) {
  return load_scene(assets_dir() + "/scenes/torus_coarse.toml", set);
}

// The floor of torus_coarse turning by deg about z through its point, at 300 deg/s.
PlaneMotion turn(double deg) {
  PlaneMotion m;
  m.omega[2] = (deg > 0 ? 1 : -1) * 300 * M_PI / 180;
  m.duration = std::fabs(deg) / 300;
  return m;
}

}  // namespace

// The speed test is armed for a floor that stops the fall. Switched off live, the body
// falls freely: no watchdog stop (it stopped this fall at 1.5 s), and the centroid follows
// g t^2 / 2 (alpha = 0).
TEST(LiveChanges, FloorSwitchedOffLetsTheBodyFallFreely) {
  Simulation sim(torus({"damping.alpha=0"}), "cpu");
  const double y0 = sim.diagnostics().centroid[1];
  sim.advance(100, 100);
  PhysicsParams p = sim.params();
  p.planes.clear();
  sim.set_params(p);
  const long n = std::lround(1.6 / sim.params().dt) - 100;
  ASSERT_NO_THROW(sim.advance(n, 1000));
  const double t = sim.time(), drop = y0 - sim.diagnostics().centroid[1];
  EXPECT_NEAR(drop, 0.5 * 9.81 * t * t, 1e-6 * drop);
}

// Switched on inside the body, the floor would throw its nodes across the depth in one
// step (the run went NaN and stayed stuck there): refused, the run going on without it.
// The start's increment du = v0 dt - a0 dt^2 / 2 holds the gravity of its time. Changed
// before the first step (Python's set_params, the viewer's panel), the start is rebuilt:
// a body at rest in zero gravity stays at rest (it drifted at g_old dt / 2: +0.35 mm in
// 0.1 s on a cube), and one whose gravity was raised falls as if started with it.
TEST(LiveChanges, GravityChangedBeforeTheFirstStepStartsFromThere) {
  for (bool adaptive : {false, true}) {
    std::vector<std::string> set = {"floor.enabled=false", "damping.alpha=0"};
    if (adaptive) set.push_back("time.dt=adaptive");
    Simulation sim(torus(set), "cpu");
    const double y0 = sim.diagnostics().centroid[1];
    PhysicsParams p = sim.params();
    p.g[1] = 0;
    sim.set_params(p);
    sim.advance_to(0.02);
    EXPECT_NEAR(sim.diagnostics().centroid[1], y0, 1e-12) << (adaptive ? "adaptive" : "auto") << ": no gravity, no motion";
    Simulation fresh(torus([&] {
                       auto s2 = set;
                       s2.push_back("gravity.g=[0,0,0]");
                       return s2;
                     }()),
                     "cpu");
    fresh.advance_to(0.02);
    EXPECT_EQ(sim.state().u, fresh.state().u) << "the same run as a scene started without gravity";
  }
}

TEST(LiveChanges, FloorSwitchedOnInsideTheBodyIsRefused) {
  Simulation sim(torus(), "cpu");
  PhysicsParams off = sim.params();
  const std::vector<PlaneSpec> floor = off.planes;
  off.planes.clear();
  sim.set_params(off);
  sim.advance(std::lround(0.024 / sim.params().dt), 100);  // the lowest point 0.6 mm below the floor's level
  ASSERT_LT(sim.gap_to(floor), -1e-4);
  PhysicsParams on = sim.params();
  on.planes = floor;
  EXPECT_THROW(sim.set_params(on), InputError);
  EXPECT_TRUE(sim.params().planes.empty());
  ASSERT_NO_THROW(sim.advance(100, 100));
  EXPECT_TRUE(std::isfinite(sim.diagnostics().centroid[1]));
}

// A reset where the floor, turned 55 degrees after the drop, cuts into the body's start is
// refused before anything changes (a probe's slope at 55 degrees: R put the torus 3.1 mm
// into it and the run was NaN 6.6 ms later); the run goes on from where it was.
TEST(LiveChanges, ResetIntoAPlaneTurnedSinceTheStartIsRefused) {
  Simulation sim(torus(), "cpu");
  sim.advance(std::lround(0.04 / sim.params().dt), 100);
  sim.set_plane_motion(0, turn(55));
  sim.advance(std::lround(0.25 / sim.params().dt), 100);  // the turn done
  const double t = sim.time();
  const std::vector<double> u = sim.state().u;
  try {
    sim.reset();
    ADD_FAILURE() << "the reset was taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reset: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("mm inside a plane as it stands now"), std::string::npos) << e.what();
  }
  EXPECT_EQ(sim.time(), t);
  EXPECT_EQ(sim.state().u, u);
  ASSERT_NO_THROW(sim.advance(100, 100));
  EXPECT_TRUE(std::isfinite(sim.diagnostics().centroid[1]));
}

// The stable model below its Poisson bound is refused live too (the panel's nu slider and
// Python's set_params reach it), and the law stays as it was.
TEST(LiveChanges, StableNeoHookeanBelowItsPoissonBoundIsRefused) {
  Simulation sim(torus(), "cpu");
  PhysicsParams p = sim.params();
  p.material_model = kStableNeoHookean;
  p.nu = -0.95;
  EXPECT_THROW(sim.set_params(p), InputError);
  EXPECT_EQ(sim.params().nu, torus().nu);
  p.nu = kMinStableNeoHookeanNu;
  EXPECT_NO_THROW(sim.set_params(p));
  EXPECT_EQ(sim.params().material_model, kStableNeoHookean);
}

// Body contact switched on live over rings that passed into each other while it was off
// is refused naming both (a probe's rings, 1.7 mm into each other, were stopped by the
// watchdog 3 ms later); switched on before they meet it is accepted, and they bounce.
TEST(LiveChanges, BodyContactSwitchedOnOverlappingIsRefused) {
  const Scene rings = load_scene(assets_dir() + "/scenes/two_ring_collision.toml");
  Simulation sim(rings, "cpu");
  PhysicsParams off = sim.params();
  off.body_contact = false;
  sim.set_params(off);
  sim.advance(std::lround(0.0045 / sim.params().dt), 100);
  PhysicsParams on = sim.params();
  on.body_contact = true;
  try {
    sim.set_params(on);
    ADD_FAILURE() << "body contact switched on over overlapping rings";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("body contact cannot be switched on: "), std::string::npos) << msg;
    EXPECT_NE(msg.find("overlap now"), std::string::npos) << msg;
  }
  EXPECT_FALSE(sim.params().body_contact);
  Simulation early(rings, "cpu");
  early.set_params(off);
  early.advance(10, 10);
  EXPECT_NO_THROW(early.set_params(on));
  early.advance(std::lround(0.04 / early.params().dt), 1000);
  const std::vector<double>& c = early.diagnostics().body_centroid;
  ASSERT_EQ(c.size(), 6u);
  EXPECT_LT(c[0], c[3]) << "the rings passed through each other";  // (ring 0 comes from -x)
}

// n steps are n steps kept: a trip the adaptive step survives rolls back, and advance
// takes the dropped steps again (it returned with none taken and the time gone back).
TEST(LiveChanges, AdaptiveAdvanceKeepsItsStepsThroughASurvivedTrip) {
  Simulation sim(torus({"gravity.g=[0,-19620,0]", "time.dt=\"adaptive\""}), "cpu");
  sim.advance(50, 50);
  EXPECT_GE(sim.watchdog_trips(), 1);
  EXPECT_EQ(sim.total_steps(), 50);
  EXPECT_GT(sim.time(), 0);
}

// reset() drops the body again with the parameters as set now: a floor still turning
// towards its angle is at that angle, as in a run given it from the start.
TEST(LiveChanges, ResetPutsATurningPlaneAtItsAngle) {
  Simulation sim(torus(), "cpu");
  const PlaneSpec flat = sim.params().planes[0];
  sim.advance(std::lround(0.04 / sim.params().dt), 100);
  sim.set_plane_motion(0, turn(20));
  sim.advance(std::lround(0.01 / sim.params().dt), 100);  // 3 of the 20 degrees
  ASSERT_TRUE(sim.plane_motion()[0].moving());
  sim.reset();
  EXPECT_FALSE(sim.plane_motion()[0].moving());
  const PlaneSpec end = moved(flat, turn(20), turn(20).duration);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(sim.params().planes[0].normal[k], end.normal[k], 1e-12);

  Simulation fresh(torus(), "cpu");
  PhysicsParams p = fresh.params();
  p.planes[0] = end;
  fresh.set_params(p);
  fresh.reset();
  const long n = std::lround(0.05 / sim.params().dt);
  sim.advance(n, 100);
  fresh.advance(n, 100);
  double d = 0;
  for (std::size_t j = 0; j < sim.state().u.size(); ++j)
    d = std::max(d, std::fabs(sim.state().u[j] - fresh.state().u[j]));
  EXPECT_LT(d, 1e-9);
}

// A rollback puts a turning plane back with the state: the pose and the turn left at the
// last healthy check (it kept the pose of the failed step's time).
TEST(LiveChanges, RollbackPutsATurningPlaneBack) {
  Simulation sim(torus({"time.allow_unstable=true", "time.dt=2e-4"}), "cpu");
  sim.set_plane_motion(0, turn(-60));
  PlaneSpec good = sim.params().planes[0];
  double left = sim.plane_motion()[0].duration;
  bool stopped = false;
  for (int i = 0; i < 400 && !stopped; ++i) {
    try {
      sim.advance(5, 5);
      good = sim.params().planes[0];
      left = sim.plane_motion()[0].duration;
    } catch (const SimulationDiverged&) {
      stopped = true;
    }
  }
  ASSERT_TRUE(stopped) << "the unstable step did not diverge";
  for (int k = 0; k < 3; ++k) EXPECT_EQ(sim.params().planes[0].normal[k], good.normal[k]);
  EXPECT_EQ(sim.plane_motion()[0].duration, left);
}

// A live change that leaves stiffness and step bounds as they are (here: none) leaves an
// adaptive run exactly as it is (it re-estimated and dropped a rung).
TEST(LiveChanges, NoOpChangeLeavesAnAdaptiveRunBitForBit) {
  Simulation a(torus({"time.dt=\"adaptive\""}), "cpu"), b(torus({"time.dt=\"adaptive\""}), "cpu");
  a.advance_to(0.03);
  b.advance_to(0.03);
  b.set_params(b.params());
  a.advance_to(0.06);
  b.advance_to(0.06);
  EXPECT_EQ(a.params().dt, b.params().dt);
  EXPECT_EQ(a.state().u, b.state().u);
}

// time.allow_unstable: the step the user insisted on stays through other live changes
// (any change clamped it to lambda dt_cr).
TEST(LiveChanges, InsistedStepStaysThroughOtherChanges) {
  Simulation sim(torus({"time.allow_unstable=true", "time.dt=1.2e-4"}), "cpu");
  ASSERT_EQ(sim.params().dt, 1.2e-4);
  PhysicsParams p = sim.params();
  p.mu = 0.3;
  EXPECT_EQ(sim.set_params(p), "");
  EXPECT_EQ(sim.params().dt, 1.2e-4);
}
