// The watchdog's state tests (step_health.h) on every backend: a NaN, a node faster than
// the scene's energy allows, an inverted element. On the GPU the step kernels and the
// per-check state kernel find them (the device watchdog: the host reads one record per
// check and no longer scans the state); on the CPU the host scans. Either way the run
// stops at the next check with the finding named, and the state is rolled back to the
// last healthy check, through advance() and through the pipelined queue()/collect().
// Faults are injected behind the facade (SolverAccess), as a blow-up would produce them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "backends.h"
#include "extreme_helpers.h"
#include "scene_helpers.h"
#include "sim/fem/step_health.h"
#include "sim/scene/solver_access.h"
#include "sim/scene/watchdog.h"

using namespace softtled;
using namespace softtled::test;

namespace {

// The box's highest node (a top corner region): moving it up stretches its elements and
// inverts none.
int top_node(const TetMesh& m) {
  int best = 0;
  for (int i = 1; i < m.nnode(); ++i)
    if (m.X[3 * i + 1] > m.X[3 * best + 1]) best = i;
  return best;
}

// A healthy run to a check: the state a rollback must restore, and its time.
struct Checked {
  HostState state;
  double t = 0;
};
Checked run_healthy(Simulation& sim) {
  sim.advance(200, 20);
  return {sim.state(), sim.time()};
}

// Runs one check interval of n steps the way `how` says ("advance" or "pipelined") and
// returns the watchdog's message, or "" when it did not stop the run.
std::string one_interval(Simulation& sim, const std::string& how, long n) {
  try {
    if (how == "advance") {
      sim.advance(n, n);
    } else {
      sim.queue(n);
      sim.collect();
    }
  } catch (const SimulationDiverged& e) {
    return e.what();
  }
  return "";
}

}  // namespace

class WatchdogHealth : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(WatchdogHealth);

// Runs the box to a healthy check, injects `fault` into node k's vertical increment (k the
// top node, dt the step) behind the facade, runs one one-step interval each way and
// expects a stop naming node k with `finding`, rolled back to that check.
template <class Fault>
void expect_stop_and_rollback(const std::string& backend, Fault fault, const std::string& finding) {
  for (const std::string how : {"advance", "pipelined"}) {
    Simulation sim(box_on_floor(""), backend);
    const Checked good = run_healthy(sim);
    const int k = top_node(sim.mesh()), n = sim.mesh().nnode();
    HostState bad = good.state;
    bad.du[std::size_t(n) + k] = fault(sim.time_step().dt);
    SolverAccess::of(sim).set_state(bad);
    const std::string msg = one_interval(sim, how, 1);
    EXPECT_NE(msg.find("node " + std::to_string(k) + " "), std::string::npos) << how << ": " << msg;
    EXPECT_NE(msg.find(finding), std::string::npos) << how << ": " << msg;
    EXPECT_EQ(sim.time(), good.t) << how;
    EXPECT_TRUE(sim.state().u == good.state.u && sim.state().du == good.state.du) << how << ": rolled back";
  }
}

// NaN in du only: after one step node k is NaN and its neighbours, which read u, are not.
TEST_P(WatchdogHealth, ANaNStopsTheRunAndRollsBack) {
  expect_stop_and_rollback(backend(), [](double) { return std::numeric_limits<double>::quiet_NaN(); }, "NaN/Inf");
}

// 20 m/s upwards (one 4 mm step) for a 10 mm box dropped from 1 mm: 10 x the bound (4 x
// its energy scale), finite, and stretching its elements, inverting none.
TEST_P(WatchdogHealth, ANodeFasterThanTheSceneAllowsStopsTheRunAndRollsBack) {
  expect_stop_and_rollback(backend(), [](double dt) { return 20.0 * dt; }, "faster than the scene's energy allows");
}

// The bound holds only where a floor stops the fall: a box sliding down an endless
// frictionless slope without damping gains kinetic energy without bound (21 m/s after
// 3 s), and must not be stopped, although its nodes end up far above the bound a floor
// would give.
TEST_P(WatchdogHealth, SpeedTestIsOffWhereGravityHasNoFloor) {
  const std::string scene =
      "units = \"mm\"\n[body]\nshape = \"box\"\nsize = [10, 10, 10]\ndivisions = [2, 2, 2]\n"
      "position = [-4.949747, 4.949747, 0]\nrotation_deg = [0, 0, 45]\n[floor]\nenabled = false\n"
      "[slope]\nenabled = true\nangle_deg = 45\npoint = [0, 0, 0]\n[contact]\nmode = \"sliding\"\n"
      "[damping]\nalpha = 0.0\n";
  Simulation sim(parse_scene(scene, "slope"), backend());
  const std::vector<double>& mass = sim.lumped_mass();
  double ke0 = 0;
  const double floor_bound =
      kNodeEnergyFactor * (watchdog_energy_scale(sim.mesh(), mass, sim.params(), ke0) + sim.diagnostics().se);
  ASSERT_NO_THROW(sim.advance(std::lround(3.0 / sim.time_step().dt), 200));
  const HostState& s = sim.state();
  const int n = sim.mesh().nnode();
  double most = 0;
  for (int i = 0; i < n; ++i) {
    double du2 = 0;
    for (int c = 0; c < 3; ++c) du2 += s.du[std::size_t(c) * n + i] * s.du[std::size_t(c) * n + i];
    most = std::max(most, 0.5 * mass[i] * du2 / (sim.time_step().dt * sim.time_step().dt));
  }
  EXPECT_GT(most, floor_bound) << "the slide must outrun the bound a floor would give, or this tests nothing";
}

// The device record itself (CUDA): the node and the element it names, and nothing on a
// healthy run.
TEST(DeviceWatchdog, RecordNamesTheNodeAndTheElement) {
  if (!backend_unavailable("cuda").empty()) GTEST_SKIP() << "no CUDA device";
  Simulation sim(box_on_floor(""), "cuda");
  Solver& solver = SolverAccess::of(sim);
  sim.advance(200, 20);
  StepHealth h = solver.take_health();
  EXPECT_TRUE(h.checked);
  EXPECT_EQ(h.bits, 0u) << "a healthy landing raised the record";
  const HostState good = sim.state();
  const TetMesh& m = sim.mesh();
  const int k = top_node(m), n = m.nnode();

  HostState bad = good;
  bad.du[k] = std::numeric_limits<double>::quiet_NaN();
  solver.set_state(bad);
  solver.step(1);
  h = solver.take_health();
  EXPECT_EQ(h.bits & kHealthNonFinite, unsigned(kHealthNonFinite));
  EXPECT_EQ(h.node, k);
  EXPECT_EQ(solver.take_health().bits & kHealthNonFinite, unsigned(kHealthNonFinite)) << "still NaN in the state";

  HostState fast = good;
  fast.du[std::size_t(n) + k] = 20.0 * sim.time_step().dt;
  solver.set_state(fast);
  EXPECT_EQ(solver.take_health().bits, unsigned(kHealthSpeed)) << "the state check";
  solver.set_state(fast);
  solver.step(1);
  h = solver.take_health();
  EXPECT_EQ(h.bits, unsigned(kHealthSpeed));
  EXPECT_EQ(h.node, k);

  // Node t[0] of element 0 mirrored through the plane of the element's other three: that
  // element (and maybe others around the node) inverted.
  const int* t = &m.tet[0];
  double p[4][3];
  for (int a = 0; a < 4; ++a)
    for (int c = 0; c < 3; ++c) p[a][c] = m.X[3 * t[a] + c] + good.u[std::size_t(c) * n + t[a]];
  double e1[3], e2[3], nrm[3];
  for (int c = 0; c < 3; ++c) e1[c] = p[2][c] - p[1][c], e2[c] = p[3][c] - p[1][c];
  nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
  nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
  nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
  const double len = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
  double d = 0;
  for (int c = 0; c < 3; ++c) d += (p[0][c] - p[1][c]) * nrm[c] / len;
  HostState inv = good;
  for (int c = 0; c < 3; ++c) inv.u[std::size_t(c) * n + t[0]] -= 2 * d * nrm[c] / len;
  solver.set_state(inv);
  h = solver.take_health();
  EXPECT_EQ(h.bits & kHealthInverted, unsigned(kHealthInverted));
  ASSERT_GE(h.element, 0);
  bool has_node = false;
  for (int a = 0; a < 4; ++a) has_node = has_node || m.tet[4 * h.element + a] == t[0];
  EXPECT_TRUE(has_node) << "element " << h.element << " does not contain the moved node";
  // The stable model handles inversion: not raised there.
  PhysicsParams q = sim.params();
  q.material_model = kStableNeoHookean;
  solver.set_params(q);
  solver.set_state(inv);
  EXPECT_EQ(solver.take_health().bits & kHealthInverted, 0u);
}

// An energy rise names its likely cause: with body-body or self-contact on, the two
// directions' pairs conflicting on non-conforming surfaces (README limits, "energy from
// body contact") first; without, a numerical blow-up.
TEST(Watchdog, EnergyRiseNamesBodyContactWhereItRuns) {
  const TetMesh m;
  const HostState s;
  StepHealth dev;
  dev.checked = true;  // the device scanned the state: only the energy test runs here
  auto cause = [&](bool body_contact) {
    Watchdog w;
    w.reset(1.0, 1.0);
    w.set_body_contact(body_contact);
    Diagnostics d;
    d.ke = 2.0;  // 1 J above the lowest energy, at a scale of 1 J
    const std::optional<WatchdogFinding> f = w.check(m, s, d, 0.0, {0}, false, Watchdog::SpeedTest{}, dev);
    return f ? f->cause : std::string("(none)");
  };
  EXPECT_NE(cause(true).find("energy from body contact"), std::string::npos) << cause(true);
  EXPECT_NE(cause(true).find("pushed by the other's triangles where the two surfaces do not conform"), std::string::npos)
      << cause(true);
  EXPECT_NE(cause(false).find("numerical blow-up; try a smaller lambda"), std::string::npos) << cause(false);
}
