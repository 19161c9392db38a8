#pragma once
// The one way past the Simulation facade to its backend, for `softtled bench` (execution
// modes, lanes, thread counts, device timing of the bare step, the CPU step's stages run
// one at a time) and backend-level tests
// (tests/solver, faults injected behind the watchdog's back). Nothing that runs, views or
// renders a scene includes this header: for them Simulation is the only door. Writes
// through it bypass the cached state() and the watchdog.
#include "sim/scene/simulation.h"

namespace softtled {

class SolverAccess {
 public:
  static Solver& of(Simulation& sim) { return *sim.solver_; }
};

}  // namespace softtled
