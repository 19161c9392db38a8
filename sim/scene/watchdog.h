#pragma once
// The watchdog Simulation::advance runs at every check: NaN/Inf, inverted elements (Taylor
// model only: its guard keeps forces finite but not meaningful) and energy gained from
// nowhere. A finding names the problem, the element and the likely cause; the Simulation
// rolls back to the last healthy check and throws SimulationDiverged with
// watchdog_message().
#include <optional>
#include <string>
#include <vector>

#include "sim/mesh/tet_mesh.h"
#include "sim/scene/diagnostics.h"
#include "sim/solver/solver.h"

namespace softtled {

struct WatchdogFinding {
  std::string problem;  // what is wrong, e.g. "element 12 is inverted (J = -0.3)"
  int element = -1;     // the element concerned, -1 when none
  std::string cause;    // the likely cause and what to do
};

class Watchdog {
 public:
  // A new energy reference (the start, a state set from outside) and the energy scale of
  // the scene, which sets what counts as a blow-up.
  void reset(double energy, double scale) { energy0_ = energy, scale_ = scale; }
  double scale() const { return scale_; }

  // Checks state s (with its diagnostics d); nothing when healthy. unstable_dt: the step is
  // above dt_cr, which then is the likely cause.
  std::optional<WatchdogFinding> check(const TetMesh& m, const HostState& s, const Diagnostics& d, MaterialModel model,
                                       bool unstable_dt);

 private:
  double energy0_ = 0, scale_ = 0;
};

// Energy scale of a scene at rest: the initial kinetic energy plus what gravity could
// release over the body's size plus its height above the lowest plane; at least 1 nJ.
double watchdog_energy_scale(const TetMesh& m, const std::vector<double>& mass, const PhysicsParams& p, double ke0);

// "watchdog stopped the run at t = ...: <problem>; dt = ... Likely cause: ... State rolled
// back to t = ..."
std::string watchdog_message(const WatchdogFinding& f, double t_bad, double t_back, double dt, double dt_cr);

}  // namespace softtled
