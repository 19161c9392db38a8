#define _USE_MATH_DEFINES
// Numerical stability at the extremes (one test each). Each asserts that the run is
// stable and physically sane, or that the watchdog stops it with a diagnosis: never
// silent garbage. Then the watchdog itself: its rollback after a live dt change, and its
// energy test (a slow gain caught at any cadence, user work and healthy runs not flagged).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>

#include "backends.h"
#include "extreme_helpers.h"
#include "scene_helpers.h"
#include "sim/scene/simulation.h"
#include "sim/scene/solver_access.h"

using namespace softtled;
using namespace softtled::test;

namespace {

// Advances in chunks and returns the largest number of nodes in contact at any check.
int advance_counting_contacts(Simulation& sim, double t_end, long check_every) {
  int most = 0;
  while (sim.time() < t_end - 1e-12) {
    sim.advance(check_every, check_every);
    most = std::max(most, sim.diagnostics().n_contact);
  }
  return most;
}

}  // namespace

class Extremes : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(Extremes);

TEST_P(Extremes, NearlyIncompressibleNu04999) {
  Simulation sim(box_on_floor("[material]\nnu = 0.4999\n"), backend());
  EXPECT_GT(sim.time_step().c, 50.0);  // c grows as 1/sqrt(1 - 2 nu): the step shrinks, auto follows
  sim.advance(std::lround(0.03 / sim.time_step().dt), 200);
  expect_sane(sim, "nu = 0.4999");
  EXPECT_GT(sim.diagnostics().n_contact, 0);
  EXPECT_GT(min_J(sim), 0.98) << "nearly incompressible: volume kept within 2 %";
}

TEST_P(Extremes, YoungsModulusFrom100PaTo1MPa) {
  for (double E : {100.0, 3e3, 1e5, 1e6}) {
    Simulation sim(box_on_floor("[material]\nE = " + std::to_string(E) + "\n"), backend());
    sim.advance(std::lround(0.03 / sim.time_step().dt), 200);
    expect_sane(sim, "E = " + std::to_string(E));
    EXPECT_NEAR(sim.time_step().dt, 0.5 * sim.time_step().dt_cr, 1e-15);
  }
}

TEST_P(Extremes, StepAboveCriticalIsRefusedOrDiagnosed) {
  Simulation probe(box_on_floor(""), backend());
  const double dt_cr = probe.time_step().dt_cr, dt_eigen = probe.time_step().dt_eigen;
  // 1.5 x dt_cr in a scene file: refused with a message naming the bound.
  try {
    Simulation sim(box_on_floor("[time]\ndt = " + std::to_string(1.5 * dt_cr) + "\n"), backend());
    ADD_FAILURE() << "dt above dt_cr accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("exceeds the stable step"), std::string::npos) << e.what();
  }
  // Forced through with allow_unstable at 1.5 x the eigenvalue bound: the watchdog stops
  // it, names dt / dt_cr and the cause, and rolls back to a finite state.
  Simulation sim(box_on_floor("[time]\nallow_unstable = true\ndt = " + std::to_string(1.5 * dt_eigen) + "\n"), backend());
  try {
    sim.advance(20000, 20);
    ADD_FAILURE() << "ran 20000 steps at 1.5 x 2/omega_max without diverging";
  } catch (const SimulationDiverged& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("x dt_cr"), std::string::npos) << msg;
    EXPECT_NE(msg.find("above the stability limit"), std::string::npos) << msg;
    for (double v : sim.state().u) ASSERT_TRUE(std::isfinite(v)) << "rollback left NaN";
  }
  // Not beyond the range every step is held to, though (2000 s ran until an element
  // turned inside out).
  EXPECT_THROW(Simulation(box_on_floor("[time]\nallow_unstable = true\ndt = 2000.0\nduration = 1e5\n"), backend()),
               InputError);
  // The same dt set live (viewer) is clamped, with a warning.
  Simulation live(box_on_floor(""), backend());
  PhysicsParams p = live.params();
  p.dt = 1.5 * dt_cr;
  p.dt_auto = false;
  const std::string warn = live.set_params(p);
  EXPECT_NE(warn.find("clamped"), std::string::npos);
  EXPECT_LE(live.time_step().dt, dt_cr);
}

// softtled run's pipelined loop (Simulation::queue / collect: on a GPU the device steps
// the next output interval while the host checks this one) gives the checks and numbers
// of advance(n, n) per interval, bit for bit, and rolls back to the same state at the same
// check when the watchdog stops a diverging run. (The CPU takes its snapshots
// synchronously: the same calls, nothing overlapping.)
TEST_P(Extremes, PipelinedChecksAreTheChecksOfAdvance) {
  auto run = [&](const Scene& sc, bool pipelined, long n, int intervals, std::vector<Diagnostics>& rows,
                 HostState& end, double& t_end) {
    Simulation sim(sc, backend());
    if (pipelined) {
      EXPECT_TRUE(sim.pipelines());
      EXPECT_EQ(SolverAccess::of(sim).async_snapshots(), backend() == "cuda") << "the GPU must really overlap";
    }
    bool diverged = false;
    try {
      if (pipelined) {
        int queued = 0;
        sim.queue(n), ++queued;
        for (int collected = 0; collected < queued; ++collected) {
          if (queued < intervals) sim.queue(n), ++queued;
          rows.push_back(sim.collect().diag);
        }
      } else {
        for (int k = 0; k < intervals; ++k) {
          sim.advance(n, n);
          rows.push_back(sim.diagnostics());
        }
      }
    } catch (const SimulationDiverged&) {
      diverged = true;
    }
    end = sim.state();
    t_end = sim.time();
    return diverged;
  };
  auto same = [](const Diagnostics& a, const Diagnostics& b) {
    return a.t == b.t && a.ke == b.ke && a.se == b.se && a.pe == b.pe && a.min_gap == b.min_gap &&
           a.n_contact == b.n_contact && a.centroid[0] == b.centroid[0] && a.centroid[1] == b.centroid[1] &&
           a.centroid[2] == b.centroid[2];
  };
  const double dt_eigen = Simulation(box_on_floor(""), backend()).time_step().dt_eigen;
  for (const std::string& extra : {std::string(""), "[time]\nallow_unstable = true\ndt = " + std::to_string(1.5 * dt_eigen) + "\n"}) {
    const Scene sc = box_on_floor(extra);
    std::vector<Diagnostics> a, b;
    HostState ea, eb;
    double ta = 0, tb = 0;
    const bool da = run(sc, false, 20, 150, a, ea, ta), db = run(sc, true, 20, 150, b, eb, tb);
    const std::string what = extra.empty() ? "a box landing" : "a step of 1.5 x 2/omega_max";
    EXPECT_EQ(da, db) << what;
    EXPECT_EQ(da, !extra.empty()) << what << ": the watchdog must stop exactly the diverging run";
    ASSERT_EQ(a.size(), b.size()) << what << ": rows before the stop";
    for (std::size_t k = 0; k < a.size(); ++k) EXPECT_TRUE(same(a[k], b[k])) << what << ", row " << k;
    EXPECT_EQ(ta, tb) << what << ": rolled back to the same check";
    EXPECT_TRUE(ea.u == eb.u && ea.du == eb.du) << what << ": the same state at the end";
    for (double v : eb.u) ASSERT_TRUE(std::isfinite(v)) << what;
  }
}

TEST_P(Extremes, FastImpactFromOneMetre) {
  // 1 m fall: 4.4 m/s at impact on a 10 mm box of soft tissue.
  for (const char* model : {"stable_neo_hookean", "neo_hookean"}) {
    // No damping, so it arrives at the full sqrt(2 g h) = 4.4 m/s.
    Simulation sim(box_on_floor(std::string("[material]\nmodel = \"") + model + "\"\nE = 30000.0\n[damping]\nalpha = 0.0\n", 1000.0), backend());
    try {
      const int contacts = advance_counting_contacts(sim, 0.5, 2);
      expect_sane(sim, model);
      EXPECT_GT(contacts, 0) << model << ": must have hit the floor";
      // Without the floor it would be 0.23 m below it by now.
      EXPECT_GT(sim.diagnostics().centroid[1], -1.006 + 0.004);
    } catch (const SimulationDiverged& e) {
      // Acceptable only for the classic model, and only as a diagnosed inversion.
      EXPECT_STREQ(model, "neo_hookean") << e.what();
      EXPECT_NE(std::string(e.what()).find("inverted"), std::string::npos) << e.what();
    }
  }
}

TEST_P(Extremes, SlopesOf0_45_89Degrees) {
  for (double angle : {0.0, 45.0, 89.0}) {
    for (const char* mode : {"sliding", "static"}) {
      // Box centred 7 mm above the slope's pivot along its normal: 2 mm gap.
      const double th = angle * M_PI / 180;
      char buf[512];
      std::snprintf(buf, sizeof buf,
                    "units = \"mm\"\n[body]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\n"
                    "position = [%.9g, %.9g, 0]\nrotation_deg = [0, 0, %.9g]\n[floor]\nenabled = false\n"
                    "[slope]\nenabled = true\nangle_deg = %.9g\npoint = [0, 0, 0]\n[contact]\nmode = \"%s\"\n",
                    -std::sin(th) * 7, std::cos(th) * 7, angle, angle, mode);
      Simulation sim(parse_scene(buf, "slope"), backend());
      const int contacts = advance_counting_contacts(sim, 0.08, 20);
      expect_sane(sim, std::to_string(angle) + " deg " + mode);
      const Diagnostics d = sim.diagnostics();
      if (angle < 89) EXPECT_GT(contacts, 0) << angle << " " << mode;
      if (angle == 89.0) EXPECT_LT(d.centroid[1], -0.02) << "on a near-vertical wall the box falls";
    }
  }
}

TEST_P(Extremes, SliverHeavyMeshRunsAtItsSmallStep) {
  // No quality bound: TetGen's plain constrained Delaunay mesh of the torus has slivers.
  Scene s = load_scene(assets_dir() + "/scenes/torus_drop.toml", {"mesh.radius_edge=0", "body.segments=[45, 9]"});
  Simulation sim(s, backend());
  const MeshQuality q = measure_quality(sim.mesh());
  EXPECT_LT(q.min_dihedral_deg, 5.0) << "expected slivers without -q";
  Scene good = load_scene(assets_dir() + "/scenes/torus_drop.toml", {"body.segments=[45, 9]"});
  Simulation ref(good, backend());
  EXPECT_LT(sim.time_step().dt_cr, ref.time_step().dt_cr) << "slivers must shrink the stable step";
  sim.advance(std::lround(0.03 / sim.time_step().dt), 500);
  expect_sane(sim, "sliver mesh");
  EXPECT_GT(sim.diagnostics().n_contact, 0);
}

TEST_P(Extremes, OneElementMesh) {
  const std::string path = ::testing::TempDir() + "one_tet.obj";
  {
    std::ofstream o(path);
    o << "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 10\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
  }
  Simulation sim(parse_scene("units = \"mm\"\n[body]\nshape = \"file\"\nfile = \"" + path +
                                 "\"\n[mesh]\nradius_edge = 0\n[floor]\nenabled = true\npoint = [0, -2, 0]\n",
                             "one tet"), backend());
  EXPECT_EQ(sim.mesh().ntet(), 1);
  const int contacts = advance_counting_contacts(sim, 0.1, 10);
  expect_sane(sim, "one element");
  EXPECT_GT(contacts, 0);
}

TEST_P(Extremes, ZeroGravityStaysExactlyAtRest) {
  Simulation sim(box_on_floor("[gravity]\ng = [0, 0, 0]\n"), backend());
  sim.advance(2000, 500);
  for (double v : sim.state().u) ASSERT_EQ(v, 0.0);
}

TEST_P(Extremes, NoDampingConservesFreeFallEnergy) {
  Scene s = box_scene("[damping]\nalpha = 0.0\n");
  Simulation sim(s, backend());
  const Diagnostics d0 = sim.diagnostics();
  sim.advance(std::lround(0.05 / sim.time_step().dt), 200);
  const Diagnostics d = sim.diagnostics();
  // Diagnostics' KE uses the half-step velocity du/dt, which lags v(t) by g dt / 2:
  // correct for it, then energy must be conserved to rounding.
  double mass = 0;
  for (double m : sim.lumped_mass()) mass += m;
  const double v_half = std::sqrt(2 * d.ke / mass), v = v_half + 9.81 * sim.time_step().dt / 2;
  EXPECT_NEAR(0.5 * mass * v * v + d.pe, d0.ke + d0.pe, 1e-5 * std::fabs(d.pe - d0.pe));
}

TEST_P(Extremes, HeavyDampingReachesTerminalVelocity) {
  Simulation sim(box_scene("[damping]\nalpha = 1000.0\n"), backend());
  sim.advance(std::lround(0.02 / sim.time_step().dt), 200);  // 20 time constants
  const HostState& st = sim.state();
  const int n = sim.mesh().nnode();
  const double v = st.du[n] / sim.time_step().dt;  // y velocity of node 0
  EXPECT_NEAR(v, -9.81 / 1000.0, 1e-3 * 9.81 / 1000.0) << "terminal velocity g / alpha";
}

// The largest damping a scene takes (alpha = 1e6 1/s): above alpha dt = 2 the increment's
// factor (2 - alpha dt) / (2 + alpha dt) is negative and the velocity flipped sign every
// step (more damping gave more kinetic energy). The step stays below 2 / alpha, and the
// body creeps from rest to g / alpha monotonically, as the damped ODE does.
TEST_P(Extremes, ExtremeDampingCreepsWithoutRinging) {
  Simulation sim(box_scene("[damping]\nalpha = 1000000.0\n"), backend());
  const double dt = sim.time_step().dt, terminal = -9.81 / 1e6;
  EXPECT_LE(dt, 2.0 / 1e6 * (1 + 1e-12));
  const int n = sim.mesh().nnode();
  double v = 0;
  for (int s = 0; s < 60; ++s) {
    sim.advance(1, 1);
    const double v_next = sim.state().du[n] / dt;  // y velocity of node 0
    ASSERT_LT(v_next, 0) << "step " << s;
    ASSERT_LE(v_next, v * (1 - 1e-9) + 1e-15) << "step " << s << ": the creep must not slow down or ring";
    ASSERT_GE(v_next, terminal * (1 + 1e-6)) << "step " << s << ": never faster than g / alpha";
    v = v_next;
  }
  EXPECT_NEAR(v, terminal, 1e-3 * std::fabs(terminal));
}

// 10^5 g crushes a 10 mm cube (classic Neo-Hookean) flat onto the floor in its first
// steps: its elements' J end between -1e-17 and 1e-16, the sign set by rounding. The run
// must stop with the watchdog whichever steps it checks at (it passed, exit 0 with
// 1e20 Pa stresses, where the checks happened to see J > 0).
TEST_P(Extremes, CrushedFlatStopsWhateverTheCheckCadence) {
  for (long every : {1L, 2L, 7L, 14L}) {
    Simulation sim(parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\n"
                               "[material]\nnu = 0.3\n[floor]\npoint = [0, -5, 0]\n[gravity]\ng = [0, -1e6, 0]\n",
                               "crush"),
                   backend());
    try {
      sim.advance(14, every);
      ADD_FAILURE() << "checks every " << every << " steps: the crushed cube ran on";
    } catch (const SimulationDiverged& e) {
      const std::string what = e.what();
      EXPECT_TRUE(what.find("has collapsed flat") != std::string::npos || what.find("is inverted") != std::string::npos)
          << every << ": " << what;
    }
  }
}

// The same crush under T4ANP: the watchdog's advice of stable_neo_hookean says that it
// needs material.element = "T4" (T4ANP takes neo_hookean only; a probe followed the advice
// and was refused), and T4's advice stays as it was.
TEST(Extremes, CrushAdviceNamesWhatStableNeoHookeanNeedsUnderT4ANP) {
  for (const std::string element : {"T4ANP", "T4"}) {
    Simulation sim(parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\n"
                               "[material]\nnu = 0.3\nelement = \"" + element + "\"\n[floor]\npoint = [0, -5, 0]\n"
                               "[gravity]\ng = [0, -1e6, 0]\n",
                               "crush"),
                   "cpu");
    try {
      sim.advance(14, 1);
      ADD_FAILURE() << element << ": the crushed cube ran on";
    } catch (const SimulationDiverged& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("stable_neo_hookean"), std::string::npos) << what;
      EXPECT_EQ(what.find("T4ANP takes neo_hookean only") != std::string::npos, element == "T4ANP") << what;
    }
  }
}

// Float rounds a position |x| to |x| 2^-24: a 10 mm cube 10 km from the origin rested
// (9,990 m up) 0.45 mm above the floor it was reported in contact with (exit 0). It says so at the
// start; at the origin, or in double, it does not.
TEST(FloatFarFromOrigin, IsReportedAtTheStart) {
  auto warning = [](const std::string& position, const std::string& precision) {
    const Scene s = parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\n"
                                "[floor]\nenabled = false\n",
                                "test", {"body.position=" + position, "solver.precision=" + precision});
    ::testing::internal::CaptureStderr();
    Simulation sim(s, "cpu");
    return ::testing::internal::GetCapturedStderr();
  };
  const std::string far = warning("[0, 9.99e6, 0]", "float");
  EXPECT_NE(far.find("float precision: nodes up to 9990 m from the origin round to 0.595 mm"), std::string::npos) << far;
  EXPECT_EQ(warning("[0, 0, 0]", "float").find("float precision"), std::string::npos);
  EXPECT_EQ(warning("[0, 9.99e6, 0]", "double").find("float precision"), std::string::npos);
}

// The same rounding reached in flight: the coarse torus thrown at 10 km/s in float is 740 m
// out at 0.074 s, where u rounds to a quarter of its smallest element edge, and the watchdog
// stops it (in double it runs). Its cause names float precision first (measured at the last
// healthy check); it had blamed the load crushing the elements.
TEST(FloatFarFromOrigin, IsNamedWhenTheRunTravelsThere) {
  Simulation sim(load_scene(assets_dir() + "/scenes/torus_coarse.toml",
                            {"solver.precision=float", "body.velocity=[1e4, 0, 0]", "time.duration=1"}),
                 "cpu");
  try {
    for (int k = 1; k <= 200; ++k) sim.advance_to(1e-3 * k);  // run's default output interval
    ADD_FAILURE() << "ran 2 km out in float without a finding";
  } catch (const SimulationDiverged& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("Likely cause: float precision: nodes"), std::string::npos) << what;
  }
}

// Stiffness damping takes the element forces at u + beta v (central_difference.h): a 6 mm
// cube (smallest element altitude 1.73 mm) landing at 5 m/s with beta = 6e-4 s (beta v =
// 3 mm, 1.7 elements) folds its bottom elements over and blows up, where it bounces at
// beta = 0 and 1e-4 s (0.29 elements). The start warns, naming beta and a safe bound, and
// the watchdog's likely cause names beta; the safe cube says nothing about it.
TEST_P(Extremes, StiffnessDampingBeyondTheElementSizeIsNamed) {
  auto drop = [&](double beta, std::string& log) {
    const Scene s = parse_scene("units = \"mm\"\n[body]\nshape = \"box\"\nsize = [6, 6, 6]\ndivisions = [2, 2, 2]\n"
                                "position = [0, 4, 0]\nvelocity = [0, -5, 0]\n[material]\nE = 50000.0\nnu = 0.3\n"
                                "[damping]\nalpha = 10.0\nbeta = " + std::to_string(beta) + "\n[floor]\nenabled = true\npoint = [0, 0, 0]\n",
                                "cube");
    ::testing::internal::CaptureStderr();
    auto sim = std::make_unique<Simulation>(s, backend());
    log = ::testing::internal::GetCapturedStderr();
    return sim;
  };
  for (double beta : {0.0, 1e-4}) {
    std::string log;
    auto sim = drop(beta, log);
    EXPECT_EQ(log.find("damping.beta"), std::string::npos) << beta << ": " << log;
    int landed = 0;
    EXPECT_NO_THROW(landed = advance_counting_contacts(*sim, 5e-3, 5)) << "beta = " << beta;
    EXPECT_GT(landed, 0) << "the cube never landed";
  }
  std::string log;
  auto sim = drop(6e-4, log);
  EXPECT_NE(log.find("warning: cube: damping.beta = 0.0006 s times the speed 5.03 m/s is 3.02 mm, 1.7 x the smallest "
                     "element (1.73 mm)"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("use damping.beta below 0.00017 s"), std::string::npos) << log;
  try {
    sim->advance(std::lround(5e-3 / sim->time_step().dt), 20);
    ADD_FAILURE() << "beta v = 1.7 elements landed without the watchdog";
  } catch (const SimulationDiverged& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("Likely cause: damping.beta = 0.0006 s times the speed"), std::string::npos) << msg;
  }
}

TEST_P(Extremes, InvertedStartRecoversWithStableNeoHookean) {
  // Start with the whole box mirrored through its centre plane x = 0 (every J = -1).
  for (const char* model : {"stable_neo_hookean", "neo_hookean"}) {
    Simulation sim(box_scene(std::string("[material]\nmodel = \"") + model + "\"\n[gravity]\ng = [0, 0, 0]\n[time]\nlambda = 0.1\n"), backend());
    HostState st = sim.state();
    const int n = sim.mesh().nnode();
    for (int i = 0; i < n; ++i) st.u[i] = -2 * sim.mesh().X[3 * i];
    sim.set_state(st);
    if (std::string(model) == "neo_hookean") {
      EXPECT_THROW(sim.advance(10, 10), SimulationDiverged) << "classic model: inversion must be reported";
      continue;
    }
    sim.advance(std::lround(0.5 / sim.time_step().dt), 500);
    expect_sane(sim, "inverted start");
    EXPECT_GT(min_J(sim), 0.5) << "stable Neo-Hookean must un-invert every element";
  }
}

TEST_P(Extremes, CrushingLoadSurvivesOrIsReported) {
  // 2000 g on a 3 kPa box against the floor flattens it completely; the stiffness of the
  // crushed state outgrows the rest-state step bound. Each model either survives or the
  // watchdog stops it with a diagnosis and a finite, rolled-back state.
  for (const char* model : {"stable_neo_hookean", "neo_hookean"}) {
    Simulation sim(box_on_floor(std::string("[material]\nmodel = \"") + model + "\"\n[gravity]\ng = [0, -20000.0, 0]\n", 0.1), backend());
    try {
      sim.advance(std::lround(0.02 / sim.time_step().dt), 5);
      expect_sane(sim, model);
    } catch (const SimulationDiverged& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("watchdog stopped the run at t = "), std::string::npos) << msg;
      EXPECT_NE(msg.find("x dt_cr"), std::string::npos) << msg;
      EXPECT_NE(msg.find("Likely cause"), std::string::npos) << msg;
      expect_sane(sim, std::string(model) + " after rollback");
    }
  }
}

TEST_P(Extremes, RollbackAfterALiveStepChangeRestoresTheSavedMotion) {
  // A box in free fall passes a check; a live E x 4 halves dt; a NaN force then makes the
  // next check fail. The rollback must restore the checked state's time and velocities,
  // in the new step's units.
  Simulation sim(box_scene(""), backend());
  const double dt1 = sim.time_step().dt;
  const long every = std::lround(5e-3 / dt1);
  sim.advance(every, every);
  const double t1 = sim.time();
  const HostState saved = sim.state();
  PhysicsParams p = sim.params();
  p.E *= 4;
  sim.set_params(p);
  const double dt2 = sim.time_step().dt;
  ASSERT_LT(dt2, 0.6 * dt1);
  EXPECT_NEAR(sim.time(), t1, 1e-15) << "time is continuous across the dt change";
  std::vector<double> f(3 * std::size_t(sim.mesh().nnode()), 0.0);
  f[0] = std::nan("");
  sim.set_external_forces(f);
  EXPECT_THROW(sim.advance(100, 50), SimulationDiverged);
  EXPECT_NEAR(sim.time(), t1, 1e-15) << "rolled back to the last good check";
  const HostState& back = sim.state();
  ASSERT_EQ(back.du.size(), saved.du.size());
  for (std::size_t j = 0; j < saved.du.size(); ++j) {
    ASSERT_EQ(back.u[j], saved.u[j]);
    const double v = saved.du[j] / dt1;
    ASSERT_NEAR(back.du[j] / dt2, v, 1e-9 * std::fabs(v)) << "velocity of dof " << j;
  }
}

TEST_P(Extremes, SlowEnergyGainIsCaughtAtAnyCheckCadence) {
  // A falling box with anti-damping (alpha < 0: energy from nowhere, a little every step)
  // must be stopped, and at about the same time whether checked every 1 ms or every 10 ms.
  double stopped_at[2] = {-1, -1};
  const double cadence[2] = {1e-3, 1e-2};
  for (int c = 0; c < 2; ++c) {
    Simulation sim(box_scene("[damping]\nalpha = 0.0\n"), backend());
    PhysicsParams p = sim.params();
    p.alpha = -2;
    sim.set_params(p);
    const long every = std::lround(cadence[c] / sim.time_step().dt);
    try {
      while (sim.time() < 0.3) sim.advance(every, every);
    } catch (const SimulationDiverged& e) {
      EXPECT_NE(std::string(e.what()).find("energy"), std::string::npos) << e.what();
      stopped_at[c] = sim.time();  // the last good check
    }
    EXPECT_GT(stopped_at[c], 0) << "a steady energy gain ran to 0.3 s at a " << cadence[c] << " s cadence";
  }
  EXPECT_NEAR(stopped_at[0], stopped_at[1], 1.1 * cadence[1]) << "stopped at the same gain, whatever the cadence";
}

TEST_P(Extremes, HealthyRunsAreNeverStopped) {
  // The watchdog's energy test on healthy runs: drops and slopes, T4 and T4ANP, every
  // contact mode, checked every 1 ms (the torus drop also every 10 ms).
  struct Case {
    const char* scene;
    std::vector<std::string> set;
    double cadence;
  };
  const std::vector<Case> cases = {
      {"torus_coarse", {}, 1e-3},
      {"torus_coarse", {}, 1e-2},
      {"torus_coarse", {"material.element=T4ANP"}, 1e-3},
      {"torus_slope_sliding", {"body.segments=[45, 9]"}, 1e-3},
      {"torus_slope_static", {"body.segments=[45, 9]"}, 1e-3},
      {"torus_slope_sliding", {"body.segments=[45, 9]", "contact.mode=coulomb", "contact.mu=0.3"}, 1e-3},
  };
  for (const Case& c : cases) {
    Simulation sim(load_scene(assets_dir() + "/scenes/" + c.scene + ".toml", c.set), backend());
    const long every = std::lround(c.cadence / sim.time_step().dt);
    std::string what = c.scene;
    for (const auto& s : c.set) what += " " + s;
    EXPECT_NO_THROW(while (sim.time() < 0.1) sim.advance(every, every)) << what;
    EXPECT_GT(sim.time(), 0.1) << what;
  }
}

TEST_P(Extremes, WorkOfUserForcesIsNotEnergyFromNowhere) {
  // A box pulled up at twice its weight gains far more energy than the watchdog's
  // tolerance; the pull did that work, so the run goes on.
  Simulation sim(box_scene("[damping]\nalpha = 0.0\n"), backend());
  const int n = sim.mesh().nnode();
  std::vector<double> f(3 * std::size_t(n), 0.0);
  for (int i = 0; i < n; ++i) f[n + i] = 2 * 9.81 * sim.lumped_mass()[i];
  sim.set_external_forces(f);
  const Diagnostics d0 = sim.diagnostics();
  const long every = std::lround(1e-3 / sim.time_step().dt);
  EXPECT_NO_THROW(while (sim.time() < 0.1) sim.advance(every, every));
  const Diagnostics d = sim.diagnostics();
  double mass = 0;
  for (double m : sim.lumped_mass()) mass += m;
  const double rise = 0.5 * 9.81 * sim.time() * sim.time();
  EXPECT_NEAR(d.centroid[1] - d0.centroid[1], rise, 0.01 * rise) << "rises at g";
  EXPECT_GT(d.ke + d.pe - d0.ke - d0.pe, 0.5 * mass * 9.81 * 0.01) << "the pull did real work";
}
