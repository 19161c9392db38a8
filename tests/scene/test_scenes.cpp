#define _USE_MATH_DEFINES
// Every shipped scene loads, runs a short time and shows the physics it is there for; and
// kinematic planes (a moving floor, a turning slope) carry the body with them.
#include <gtest/gtest.h>

#include <cmath>

#include "backends.h"
#include "scene_helpers.h"
#include "sim/scene/simulation.h"

using namespace softtled;
using namespace softtled::test;

namespace {

Scene scene(const std::string& name, const std::vector<std::string>& set = {}) {
  return load_scene(assets_dir() + "/scenes/" + name + ".toml", set);
}

void run_to(Simulation& sim, double t) { sim.advance(std::lround((t - sim.time()) / sim.time_step().dt), 200); }

// Centroid velocity and angular velocity about z (from the angular momentum of the
// nodal masses about the centroid, divided by the moment of inertia).
struct Motion {
  double v[3], omega_z;
};
Motion motion(Simulation& sim) {
  const HostState& st = sim.state();
  const auto& m = sim.lumped_mass();
  const int n = sim.mesh().nnode();
  const double dt = sim.time_step().dt;
  double M = 0, c[3] = {0, 0, 0}, p[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    M += m[i];
    for (int k = 0; k < 3; ++k) {
      c[k] += m[i] * (sim.mesh().X[3 * i + k] + st.u[k * n + i]);
      p[k] += m[i] * st.du[k * n + i] / dt;
    }
  }
  Motion r;
  for (int k = 0; k < 3; ++k) c[k] /= M, r.v[k] = p[k] / M;
  double L = 0, I = 0;
  for (int i = 0; i < n; ++i) {
    const double x = sim.mesh().X[3 * i] + st.u[i] - c[0], y = sim.mesh().X[3 * i + 1] + st.u[n + i] - c[1];
    const double vx = st.du[i] / dt - r.v[0], vy = st.du[n + i] / dt - r.v[1];
    L += m[i] * (x * vy - y * vx);
    I += m[i] * (x * x + y * y);
  }
  r.omega_z = L / I;
  return r;
}

// A 10 mm box resting on a floor at y = -5 mm (its bottom face).
Scene box_on_floor(const std::string& extra = "") {
  return parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\n"
                     "[floor]\nenabled = true\npoint = [0, -5, 0]\n" + extra,
                     "box on floor");
}

double downhill(const Diagnostics& a, const Diagnostics& b, double theta_deg) {
  const double th = theta_deg * M_PI / 180;
  return -(b.centroid[0] - a.centroid[0]) * std::cos(th) - (b.centroid[1] - a.centroid[1]) * std::sin(th);
}

}  // namespace

TEST(Scenes, TorusOnSlopeRollsWithStaticFrictionAndSlidesWithout) {
  double dist[2];
  for (int k = 0; k < 2; ++k) {
    Simulation sim(scene(k == 0 ? "torus_slope_static" : "torus_slope_sliding", {"body.segments=[45, 9]"}));
    const Diagnostics d0 = sim.diagnostics();
    run_to(sim, 0.25);
    dist[k] = downhill(d0, sim.diagnostics(), 30);
    const Motion mo = motion(sim);
    const double speed = std::hypot(mo.v[0], mo.v[1]);
    if (k == 0) EXPECT_NEAR(std::fabs(mo.omega_z) * 10e-3 / speed, 1.0, 0.2) << "static: rolls without slipping";
    else EXPECT_LT(std::fabs(mo.omega_z) * 10e-3 / speed, 0.1) << "sliding: no rotation";
  }
  // Rolling ring on its outer radius: a = g sin / (1 + (R^2 + 3/4 r^2) / R_out^2) -> 0.62 of sliding.
  EXPECT_NEAR(dist[0] / dist[1], 1 / (1 + (7.5 * 7.5 + 0.75 * 2.5 * 2.5) / 100.0), 0.06);
}

TEST(Scenes, SphereRollsWithStaticFrictionAndSlidesWithout) {
  double dist[2];
  for (int k = 0; k < 2; ++k) {
    Simulation sim(scene("sphere_slope", {"body.subdivisions=2", k == 0 ? "contact.mode=static" : "contact.mode=sliding"}));
    const Diagnostics d0 = sim.diagnostics();
    run_to(sim, 0.3);
    dist[k] = downhill(d0, sim.diagnostics(), 30);
    const Motion mo = motion(sim);
    const double ratio = std::fabs(mo.omega_z) * 5e-3 / std::hypot(mo.v[0], mo.v[1]);
    if (k == 0) EXPECT_NEAR(ratio, 1.0, 0.2) << "static: omega R = v";
    else EXPECT_LT(ratio, 0.1) << "sliding: no rotation";
  }
  EXPECT_NEAR(dist[0] / dist[1], 5.0 / 7.0, 0.06) << "solid sphere rolls at 5/7 of the sliding acceleration";
}

TEST(Scenes, CubeSettlesUnderItsWeightAsUniaxialTheoryPredicts) {
  Simulation sim(scene("cube_rest"));
  run_to(sim, 0.2);
  const Diagnostics d = sim.diagnostics();
  const double E = 3000, rho = 1000, g = 9.81, L = 0.01;
  EXPECT_NEAR(-d.tracked[1], rho * g * L * L / (2 * E), 0.05 * rho * g * L * L / (2 * E)) << "top-face settlement";
  EXPECT_NEAR(-d.centroid[1], rho * g * L * L / (3 * E), 0.05 * rho * g * L * L / (3 * E)) << "centroid settlement";
  EXPECT_LT(d.ke, 1e-12) << "at rest";
}

TEST(Scenes, CantileverTipApproachesBeamTheoryWithRefinement) {
  const double E = 1e6, rho = 1000, g = 9.81, h = 4e-3, L = 40e-3;
  const double delta = rho * g * h * h * std::pow(L, 4) / (8 * E * std::pow(h, 4) / 12);
  double tip[2];
  for (int k = 0; k < 2; ++k) {
    Simulation sim(scene("beam_cantilever", {k == 0 ? "mesh.max_volume=2.0" : "mesh.max_volume=0.5", "time.lambda=0.9"}));
    EXPECT_GT(sim.fixed_node_count(), 8);
    run_to(sim, 0.1);
    tip[k] = -sim.diagnostics().tracked[1];
  }
  EXPECT_LT(tip[0], tip[1]) << "linear tets are too stiff in bending; refining must soften the beam";
  EXPECT_NEAR(tip[1], delta, 0.25 * delta) << "Euler-Bernoulli q L^4 / 8EI";
  EXPECT_LT(tip[1], delta * 1.02);
}

TEST(Scenes, CoarseAndFineToriBracketThePaperMesh) {
  Simulation coarse(scene("torus_coarse"));
  Simulation paper(scene("torus_drop"));
  Simulation fine(scene("torus_fine"));
  EXPECT_LT(coarse.mesh().ntet(), paper.mesh().ntet());
  // The paper's r_sub column has 27918 tets; TetGen 1.5 -pq2 inserts more interior points.
  EXPECT_NEAR(fine.mesh().ntet(), 27918, 0.2 * 27918) << "the paper's r_sub column";
  EXPECT_GT(coarse.time_step().dt_cr, paper.time_step().dt_cr);
  // The fine torus falls freely like the others: 2 ms of damped free fall.
  const double y0 = fine.diagnostics().centroid[1];
  run_to(fine, 0.002);
  const double t = fine.time();
  EXPECT_NEAR(y0 - fine.diagnostics().centroid[1], (9.81 / 10) * (t - (1 - std::exp(-10 * t)) / 10), 1e-2 * 2e-5);
}

class KinematicPlanes : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(KinematicPlanes);

TEST_P(KinematicPlanes, RisingFloorCarriesTheBody) {
  // The floor rises at 0.1 m/s for 50 ms: the box rides on it, 5 mm up, at its speed.
  const double v = 0.1, T = 0.05;
  Simulation still(box_on_floor(), backend()), lift(box_on_floor(), backend());
  PlaneMotion up;
  up.velocity[1] = v;
  up.duration = T;
  lift.set_plane_motion(0, up);
  const double floor0 = lift.params().planes[0].point[1];
  const long every = std::lround(1e-3 / lift.time_step().dt);
  double rise_half = 0;  // rise relative to the still floor's run at T / 2
  auto rise = [&] { return lift.diagnostics().centroid[1] - still.diagnostics().centroid[1]; };
  while (lift.time() < T + 1e-12) {
    lift.advance(every, every);
    still.advance(every, every);
    ASSERT_GT(lift.diagnostics().min_gap, -1e-9) << "a node behind the moving floor at t = " << lift.time();
    if (lift.time() <= T / 2 + 1e-12) rise_half = rise();
  }
  EXPECT_FALSE(lift.plane_motion()[0].moving()) << "the motion stops after its duration";
  EXPECT_NEAR(lift.params().planes[0].point[1] - floor0, v * T, 1e-12) << "the floor moved v T exactly";
  EXPECT_NEAR(rise(), v * T, 0.1 * v * T) << "the body rose with the floor";
  EXPECT_NEAR((rise() - rise_half) / (T / 2), v, 0.1 * v) << "at its speed, once carried";
}

TEST_P(KinematicPlanes, TurningSlopeTiltsTheBodyAndStopsAtItsAngle) {
  // A slope under the box, pivoting about its left edge, turns from 0 to 10 deg in 0.1 s
  // and lifts the box (static friction: it does not slide down) with it.
  Scene s = box_on_floor("[slope]\nenabled = true\nangle_deg = 0.0\npoint = [-5, -5, 0]\n[contact]\nmode = \"static\"\n");
  s.floor = false;
  Simulation sim(s, backend());
  PlaneMotion turn;
  turn.omega[2] = 100 * M_PI / 180;
  turn.duration = 0.1;
  sim.set_plane_motion(0, turn);
  const Diagnostics d0 = sim.diagnostics();
  const long every = std::lround(2e-3 / sim.time_step().dt);
  while (sim.time() < 0.1 + 1e-12) {
    sim.advance(every, every);
    ASSERT_GT(sim.diagnostics().min_gap, -1e-9) << "a node behind the turning slope at t = " << sim.time();
  }
  EXPECT_FALSE(sim.plane_motion()[0].moving());
  EXPECT_NEAR(slope_angle_deg(s, sim.params().planes[0]), 10.0, 1e-9);
  EXPECT_GT(sim.diagnostics().centroid[1] - d0.centroid[1], 0.3e-3) << "the slope lifted the box (by ~0.9 mm at rest)";
}
