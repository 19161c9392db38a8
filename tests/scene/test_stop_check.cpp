// Simulation's stop check (set_stop_check: how `run` answers a signal) on every backend:
// called before the first step and then every kStopCheckSteps steps of advance() and of a
// queued interval, pipelined or not; true stops the steps at once, unchecked, and says so
// (stopped_early, Checkpoint::stopped); false never changes the steps taken.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "backends.h"
#include "extreme_helpers.h"
#include "sim/scene/simulation.h"

using namespace softtled;
using namespace softtled::test;

namespace {

constexpr long kLong = 5 * Simulation::kStopCheckSteps;

// A check that answers false `calls_before_stop` times, then true.
std::function<bool()> stop_after(int calls_before_stop, int* calls) {
  return [=] { return ++*calls > calls_before_stop; };
}

}  // namespace

class StopCheck : public OnEachBackend {};
SOFTTLED_ON_EACH_BACKEND(StopCheck);

// A long output interval (time.output_every spanning many steps) stops within
// kStopCheckSteps of the stop: two checks pass (before the first step and after it, the
// step that times the chunk), the third stops the queued steps at most kStopCheckSteps
// later (exactly that many here: a box's step is far below kStopCheckWallS / 1000).
TEST_P(StopCheck, AQueuedIntervalStopsWithinKStopCheckSteps) {
  for (const bool user_force : {false, true}) {  // pipelined, and collect() stepping itself
    SCOPED_TRACE(user_force ? "not pipelined (a user force)" : "pipelined");
    Simulation sim(box_on_floor(""), backend());
    if (user_force) sim.set_external_forces(std::vector<double>(3 * std::size_t(sim.mesh().nnode()), 1e-6));
    ASSERT_EQ(sim.pipelines(), !user_force);
    int calls = 0;
    sim.set_stop_check(stop_after(2, &calls));
    sim.queue(kLong);
    const Simulation::Checkpoint& c = sim.collect();
    EXPECT_TRUE(c.stopped);
    EXPECT_EQ(calls, 3);
    EXPECT_GT(sim.total_steps(), 1);
    EXPECT_LE(sim.total_steps(), 1 + Simulation::kStopCheckSteps);
  }
}

TEST_P(StopCheck, AdvanceStopsWithinKStopCheckStepsWithoutItsCheck) {
  Simulation sim(box_on_floor(""), backend());
  int calls = 0;
  sim.set_stop_check(stop_after(0, &calls));  // the first call stops: before any step
  sim.advance(kLong, kLong);
  EXPECT_TRUE(sim.stopped_early());
  EXPECT_EQ(sim.total_steps(), 0);
  calls = 0;
  sim.set_stop_check(stop_after(1, &calls));
  sim.advance(kLong, kLong);
  EXPECT_TRUE(sim.stopped_early());
  EXPECT_EQ(sim.total_steps(), 1);  // the first step is timed alone (Simulation::kStopCheckWallS)
  sim.set_stop_check({});
  sim.advance(10, 10);
  EXPECT_FALSE(sim.stopped_early());
}

// A check that never stops leaves the run bit for bit as one without a check.
TEST_P(StopCheck, ACheckThatNeverStopsChangesNothing) {
  Simulation plain(box_on_floor(""), backend()), checked(box_on_floor(""), backend());
  int calls = 0;
  checked.set_stop_check(stop_after(1 << 30, &calls));
  const long n = 2 * Simulation::kStopCheckSteps + 37;
  plain.queue(n);
  checked.queue(n);
  const Simulation::Checkpoint& a = plain.collect();
  EXPECT_FALSE(a.stopped);
  const HostState sa = a.state;
  const Simulation::Checkpoint& b = checked.collect();
  EXPECT_FALSE(b.stopped);
  EXPECT_GE(calls, 4);  // before the first step, after it, then at most every kStopCheckSteps
  EXPECT_TRUE(sa.u == b.state.u && sa.du == b.state.du);
  plain.advance(n, 500);
  checked.advance(n, 500);
  EXPECT_TRUE(plain.state().u == checked.state().u && plain.state().du == checked.state().du);
  EXPECT_EQ(plain.total_steps(), 2 * n);
}
