#define _USE_MATH_DEFINES
// The adaptive step (time.dt = "adaptive": dt = lambda * 2 / omega_max of the live state,
// estimated while the run goes): the variable-step central difference against the
// analytic damped fall, the paper's drop in fewer steps with the same first impact, a
// fixed step that diverges where the adaptive one runs through, the extremes of
// test_extremes.cpp with the adaptive step, and its last line of defence (a watchdog trip
// rolls back, halves lambda and goes on; repeated trips stop the run).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "backends.h"
#include "extreme_helpers.h"
#include "scene_helpers.h"
#include "sim/scene/simulation.h"
#include "sim/scene/solver_access.h"

using namespace softtled;
using namespace softtled::test;

namespace {

const std::string kAdaptive = "[time]\ndt = \"adaptive\"\n";

// advance_to in output intervals of `every` s; returns the most nodes in contact.
int run_to(Simulation& sim, double t_end, double every) {
  int most = 0;
  for (double t = every; t < t_end + 0.5 * every; t += every) {
    sim.advance_to(std::min(t, t_end));
    most = std::max(most, sim.diagnostics().n_contact);
  }
  return most;
}

}  // namespace

class VariableStep : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(VariableStep);

TEST_P(VariableStep, FreeFallFollowsTheAnalyticDampedCurve) {
  // dt changes every 100 steps through 10, 14, 7, 12, 9 us (live, as the adaptive step
  // does): du is rescaled and the first step after each change spans the midpoint step.
  const double dts[] = {10e-6, 14e-6, 7e-6, 12e-6, 9e-6};
  for (const char* prec : {"double", "float"}) {
    Simulation sim(box_scene(std::string("[time]\ndt = 1e-5\n[solver]\nprecision = \"") + prec + "\"\n"), backend());
    const double y0 = sim.diagnostics().centroid[1];
    double worst = 0;
    for (int c = 0; c < 50; ++c) {
      PhysicsParams p = sim.params();
      p.dt = dts[c % 5];
      sim.set_params(p);
      sim.step(100);
      const double t = sim.time();
      const double drop = y0 - sim.diagnostics().centroid[1];
      worst = std::max(worst, std::fabs(drop / damped_fall(9.81, 10.0, t) - 1));
    }
    std::printf("%s, %s: dt changing every 100 steps, largest relative error of the fall %.3g (t = %.4f s)\n",
                backend().c_str(), prec, worst, sim.time());
    EXPECT_LT(worst, 1e-3) << prec;
    EXPECT_NEAR(sim.time(), 10 * 100 * (10 + 14 + 7 + 12 + 9) * 1e-6, 1e-12);
  }
}

class AdaptiveRun : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(AdaptiveRun);

TEST_P(AdaptiveRun, PaperDropHasTheFirstImpactOfAutoInFewerSteps) {
  // The paper's drop (T4, sliding floor) to past the first impact: the largest centroid
  // drop (at ~0.056 s) within 0.5 % of the auto step's, in at most 1/2.5 of its steps.
  const Scene s = load_scene(assets_dir() + "/scenes/torus_drop.toml", {});
  Scene sa = s;
  sa.dt_auto = false;
  sa.dt_adaptive = true;
  double drop[2] = {0, 0};
  long steps[2] = {0, 0};
  for (int j = 0; j < 2; ++j) {
    Simulation sim(j == 0 ? s : sa, backend());
    const double y0 = sim.diagnostics().centroid[1];
    for (double t = 0.0005; t < 0.0705; t += 0.0005) {
      sim.advance_to(t);
      if (t > 0.04) drop[j] = std::max(drop[j], y0 - sim.diagnostics().centroid[1]);
    }
    steps[j] = sim.total_steps();
    std::printf("%s: %s step, %ld steps to %.4f s (dt %.3g-%.3g us), largest centroid drop %.4f mm\n",
                backend().c_str(), j ? "adaptive" : "auto", steps[j], sim.time(), sim.dt_min_used() * 1e6,
                sim.dt_max_used() * 1e6, drop[j] * 1e3);
  }
  EXPECT_NEAR(drop[1], drop[0], 0.005 * drop[0]);
  EXPECT_LE(2.5 * steps[1], steps[0]);
}

TEST_P(AdaptiveRun, CompressionThatDivergesAtAFixedThirtyMicrosecondsRunsThrough) {
  // The paper's drop at a fixed 30 us (above 2/omega_max of the compressed state, below
  // that of the rest state) blows up at the first compression; the adaptive step follows
  // the stiffening and lands, without a single watchdog trip.
  const Scene s = load_scene(assets_dir() + "/scenes/torus_drop.toml",
                             {"time.dt=30e-6", "time.allow_unstable=true"});
  {
    Simulation sim(s, backend());
    EXPECT_THROW(run_to(sim, 0.1, 0.001), SimulationDiverged);
  }
  Scene sa = s;
  sa.dt_adaptive = true;
  sa.allow_unstable = false;
  Simulation sim(sa, backend());
  const int contacts = run_to(sim, 0.1, 0.001);
  expect_sane(sim, "adaptive drop");
  EXPECT_EQ(sim.watchdog_trips(), 0);
  EXPECT_GT(contacts, 0);
  EXPECT_NEAR(sim.time(), 0.1, sim.time_step().dt);
  EXPECT_LT(sim.dt_min_used(), sim.dt_max_used()) << "the step must have followed the compression";
  std::printf("%s: adaptive step %.3g-%.3g us, %ld steps, live 2/omega_max now %.3g us\n", backend().c_str(),
              sim.dt_min_used() * 1e6, sim.dt_max_used() * 1e6, sim.total_steps(), sim.time_step().dt_live * 1e6);
}

TEST_P(AdaptiveRun, TimeDtMaxCapsTheStep) {
  Simulation sim(box_on_floor(kAdaptive + "dt_max = 2e-5\n"), backend());
  run_to(sim, 0.01, 0.001);
  EXPECT_LE(sim.dt_max_used(), 2e-5);
  EXPECT_GT(sim.dt_max_used(), 0.9 * 2e-5 / std::exp2(1.0 / softtled::AdaptiveStep::kRungsPerOctave));
}

// A live call that leaves the step's bounds as they are keeps the step and its live bound
// (a probe's finds): a no-op set_params put dt_cr back to its rest value until the next
// estimate, and an alpha whose 2/alpha is far above the step re-estimated it. An alpha
// whose bound cuts the step still shortens it at once.
TEST(AdaptiveLive, CallsThatLeaveTheBoundsKeepTheStepAndItsLiveBound) {
  Simulation sim(load_scene(assets_dir() + "/scenes/torus_coarse.toml", {"time.dt=adaptive"}), "cpu");
  sim.advance_to(0.03);
  const double dt = sim.params().dt, dt_cr = sim.time_step().dt_cr;
  ASSERT_GT(sim.time_step().dt_live, 0);
  ASSERT_NE(dt_cr, sim.time_step().dt_eigen) << "the live bound differs from the rest one here";
  sim.set_params(sim.params());
  EXPECT_EQ(sim.time_step().dt_cr, dt_cr) << "a no-op call changed the live bound";
  EXPECT_EQ(sim.params().dt, dt);
  PhysicsParams p = sim.params();
  p.alpha = 10.5;  // 2/alpha = 0.19 s
  sim.set_params(p);
  EXPECT_EQ(sim.params().dt, dt);
  EXPECT_EQ(sim.time_step().dt_cr, dt_cr);
  p.alpha = 2.0 / dt;  // 2/alpha = dt: lambda 2/alpha is below the step
  sim.set_params(p);
  EXPECT_LT(sim.params().dt, dt);
  EXPECT_EQ(sim.time_step().dt_cr, 2.0 / p.alpha);
}

// ---- the extremes of test_extremes.cpp with the adaptive step ----

class AdaptiveExtremes : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(AdaptiveExtremes);

TEST_P(AdaptiveExtremes, NearlyIncompressibleNu04999) {
  Simulation sim(box_on_floor("[material]\nnu = 0.4999\n" + kAdaptive), backend());
  EXPECT_GT(run_to(sim, 0.03, 0.001), 0);  // it bounces: contacts at some checks, not all
  expect_sane(sim, "nu = 0.4999");
  EXPECT_GT(min_J(sim), 0.98);
}

TEST_P(AdaptiveExtremes, YoungsModulusFrom100PaTo1MPa) {
  for (double E : {100.0, 3e3, 1e5, 1e6}) {
    Simulation sim(box_on_floor("[material]\nE = " + std::to_string(E) + "\n" + kAdaptive), backend());
    run_to(sim, 0.03, 0.001);
    expect_sane(sim, "E = " + std::to_string(E));
    EXPECT_LE(sim.time_step().dt, 0.5 * sim.time_step().dt_live * (1 + 1e-12)) << E;
  }
}

TEST_P(AdaptiveExtremes, FastImpactFromOneMetre) {
  for (const char* model : {"stable_neo_hookean", "neo_hookean"}) {
    Simulation sim(box_on_floor(std::string("[material]\nmodel = \"") + model +
                                    "\"\nE = 30000.0\n[damping]\nalpha = 0.0\n" + kAdaptive,
                                1000.0),
                   backend());
    try {
      const int contacts = run_to(sim, 0.5, 0.0005);
      expect_sane(sim, model);
      EXPECT_GT(contacts, 0) << model;
      EXPECT_GT(sim.diagnostics().centroid[1], -1.006 + 0.004);
    } catch (const SimulationDiverged& e) {
      EXPECT_STREQ(model, "neo_hookean") << e.what();
      EXPECT_NE(std::string(e.what()).find("inverted"), std::string::npos) << e.what();
    }
  }
}

TEST_P(AdaptiveExtremes, CrushingLoadSurvivesOrIsReported) {
  for (const char* model : {"stable_neo_hookean", "neo_hookean"}) {
    Simulation sim(box_on_floor(std::string("[material]\nmodel = \"") + model + "\"\n[gravity]\ng = [0, -20000.0, 0]\n" +
                                    kAdaptive,
                                0.1),
                   backend());
    try {
      run_to(sim, 0.02, 0.0002);
      expect_sane(sim, model);
      std::printf("%s, %s: 2000 g crush survived, step %.3g-%.3g us, %d watchdog trips\n", backend().c_str(), model,
                  sim.dt_min_used() * 1e6, sim.dt_max_used() * 1e6, sim.watchdog_trips());
    } catch (const SimulationDiverged& e) {
      const std::string msg = e.what();
      std::printf("%s, %s: 2000 g crush stopped: %s\n", backend().c_str(), model, msg.c_str());
      EXPECT_NE(msg.find("watchdog stopped the run at t = "), std::string::npos) << msg;
      expect_sane(sim, std::string(model) + " after rollback");
    }
  }
}

TEST_P(AdaptiveExtremes, InvertedStartRecoversWithStableNeoHookean) {
  Simulation sim(box_scene("[material]\nmodel = \"stable_neo_hookean\"\n[gravity]\ng = [0, 0, 0]\n" + kAdaptive +
                           "lambda = 0.1\n"),
                 backend());
  HostState st = sim.state();
  const int n = sim.mesh().nnode();
  for (int i = 0; i < n; ++i) st.u[i] = -2 * sim.mesh().X[3 * i];
  sim.set_state(st);
  run_to(sim, 0.5, 0.001);
  expect_sane(sim, "inverted start");
  EXPECT_GT(min_J(sim), 0.5);
}

TEST_P(AdaptiveExtremes, HeavyDampingReachesTerminalVelocity) {
  Simulation sim(box_scene("[damping]\nalpha = 1000.0\n" + kAdaptive), backend());
  run_to(sim, 0.02, 0.001);
  const HostState& st = sim.state();
  const int n = sim.mesh().nnode();
  const double v = st.du[n] / sim.time_step().dt;
  EXPECT_NEAR(v, -9.81 / 1000.0, 1e-3 * 9.81 / 1000.0);
}

TEST_P(AdaptiveExtremes, SliverHeavyMeshRunsAtALargerStep) {
  // Slivers set Le/c (the auto step's bound) far below the real limit; the adaptive step
  // follows 2/omega_max instead.
  Scene s = load_scene(assets_dir() + "/scenes/torus_drop.toml", {"mesh.radius_edge=0", "body.segments=[45, 9]"});
  Simulation auto_sim(s, backend());
  s.dt_auto = false;
  s.dt_adaptive = true;
  Simulation sim(s, backend());
  EXPECT_LT(measure_quality(sim.mesh()).min_dihedral_deg, 5.0);
  run_to(sim, 0.03, 0.001);
  expect_sane(sim, "sliver mesh");
  EXPECT_GT(sim.diagnostics().n_contact, 0);
  EXPECT_GT(sim.dt_min_used(), auto_sim.time_step().dt);
}

// ---- the last line of defence ----

// softtled run's pipelined loop with the adaptive step (Simulation::queue_until / collect:
// each check runs an interval behind the live state, at its snapshot's own time, step and
// controller state) gives the rows and states of advance_to per interval, bit for bit,
// including a watchdog trip the adaptive step survives: both roll back to the same check,
// halve lambda from the same controller state and step the interval again.
TEST_P(AdaptiveRun, PipelinedRunIsTheRunOfAdvanceTo) {
  // The coarse paper drop through its first impact (~0.05 s), where the step moves.
  const Scene sc = load_scene(assets_dir() + "/scenes/torus_drop.toml", {"body.segments=[45, 9]", "time.dt=adaptive"});
  const double every = 0.002;
  const int intervals = 35, fault_after = 25;  // the fault injected at the 50 ms check
  // The fault: one node flung up at 20 m/s, behind the facade. Finite, so the estimates
  // made on it still move the step (a NaN would freeze the controller until the check).
  auto inject = [](Simulation& sim) {
    HostState bad = sim.state();
    const int n = sim.mesh().nnode();
    int top = 0;
    for (int i = 1; i < n; ++i)
      if (sim.mesh().X[3 * i + 1] > sim.mesh().X[3 * top + 1]) top = i;
    bad.du[std::size_t(n) + top] = 20.0 * sim.time_step().dt;
    SolverAccess::of(sim).set_state(bad);
  };
  auto same = [](const Diagnostics& a, const Diagnostics& b) {
    return a.t == b.t && a.ke == b.ke && a.se == b.se && a.pe == b.pe && a.min_gap == b.min_gap &&
           a.n_contact == b.n_contact && a.centroid[0] == b.centroid[0] && a.centroid[1] == b.centroid[1] &&
           a.centroid[2] == b.centroid[2];
  };
  // advance_to per interval.
  Simulation a(sc, backend());
  std::vector<Diagnostics> rows_a;
  for (int k = 1; k <= intervals; ++k) {
    a.advance_to(k * every);
    rows_a.push_back(a.diagnostics());
    if (k == fault_after) inject(a);
  }
  // queue_until / collect, two intervals in flight except around the injection (which
  // must hit the state of the 50 ms check, as above).
  Simulation b(sc, backend());
  EXPECT_TRUE(b.pipelines());
  std::vector<Diagnostics> rows_b;
  int queued = 0, rollbacks = 0;
  auto queue_next = [&] { b.queue_until(++queued * every); };
  queue_next();
  while (int(rows_b.size()) < intervals) {
    if (queued < intervals && queued != fault_after) queue_next();
    const Simulation::Checkpoint& c = b.collect();
    if (c.rolled_back) {  // the run loop's answer: queue again from the restored check
      ++rollbacks;
      queued = int(rows_b.size());
      queue_next();
      continue;
    }
    rows_b.push_back(c.diag);
    if (int(rows_b.size()) == fault_after) {
      inject(b);
      queue_next();
    }
  }
  EXPECT_EQ(rollbacks, 1);
  EXPECT_EQ(a.watchdog_trips(), 1);
  EXPECT_EQ(b.watchdog_trips(), 1);
  ASSERT_EQ(rows_a.size(), rows_b.size());
  for (std::size_t k = 0; k < rows_a.size(); ++k)
    EXPECT_TRUE(same(rows_a[k], rows_b[k])) << "row " << k << ": t " << rows_a[k].t << " / " << rows_b[k].t << ", ke "
                                            << rows_a[k].ke << " / " << rows_b[k].ke;
  EXPECT_EQ(a.total_steps(), b.total_steps());
  EXPECT_EQ(a.time(), b.time());
  EXPECT_EQ(a.time_step().dt, b.time_step().dt);
  EXPECT_TRUE(a.state().u == b.state().u && a.state().du == b.state().du) << "final states differ";
  expect_sane(b, "pipelined, after the trip");
}

TEST_P(AdaptiveRun, WatchdogTripRollsBackHalvesLambdaAndGoesOn) {
  Simulation sim(box_on_floor(kAdaptive), backend());
  sim.advance_to(0.005);
  const double dt_before = sim.time_step().dt;
  // A one-off corruption behind the watchdog's back (the backend hatch): NaN at one node.
  HostState bad = sim.state();
  bad.u[0] = std::numeric_limits<double>::quiet_NaN();
  SolverAccess::of(sim).set_state(bad);
  sim.advance_to(0.006);  // trips, rolls back to 0.005 s, goes on at half lambda
  EXPECT_LT(sim.time_step().dt, 0.75 * dt_before);
  run_to(sim, 0.05, 0.001);
  expect_sane(sim, "after a trip");
  EXPECT_NEAR(sim.time(), 0.05, sim.time_step().dt);
  // A persistent fault (a NaN user force): stopped after kMaxFailures trips.
  std::vector<double> f(3 * sim.mesh().nnode(), 0.0);
  f[0] = std::numeric_limits<double>::quiet_NaN();
  sim.set_external_forces(f);
  EXPECT_THROW(run_to(sim, 0.1, 0.001), SimulationDiverged);
  expect_sane(sim, "after the stop");
}
