#pragma once
// The watchdog Simulation::advance runs at every check: NaN/Inf, inverted elements (Taylor
// model only: its guard keeps forces finite but not meaningful), a node faster than the
// scene's energy allows (step_health.h) and energy gained from nowhere. A finding names the problem, the element and the likely cause; the Simulation
// rolls back to the last healthy check and throws SimulationDiverged with
// watchdog_message().
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "sim/mesh/tet_mesh.h"
#include "sim/scene/diagnostics.h"
#include "sim/solver/solver.h"

namespace softtled {

struct WatchdogFinding {
  std::string problem;  // what is wrong, e.g. "element 12 is inverted (J = -0.3)" (of body[i]: node_name)
  int element = -1;     // the element concerned (the whole mesh's number), -1 when none
  std::string cause;    // the likely cause and what to do
};

// The energy test: with alpha >= 0 and passive contact, H = ke + se + pe - W (W the work
// of the user's forces) can only fall. A check fails when H exceeds the lowest H of any
// check since the reference was set by more than kEnergyTolerance x the scene's energy
// scale: a steady gain is caught however small, at any check cadence. The tolerance is
// for what the measured H does in healthy runs: ke uses the half-step velocity, which
// around an impact is off by up to the impact's kinetic energy (a 10 mm box landing at
// 4.4 m/s with alpha = 0, checked every 2 steps, rises 7 % of its scale above its lowest).
class Watchdog {
 public:
  static constexpr double kEnergyTolerance = 0.15;

  // A new reference: h0 = ke + se + pe - W of a state set from outside (the start, a
  // user's state), and the energy scale of the scene.
  void reset(double h0, double scale) { h_min_ = h0, have_min_ = true, scale_ = scale; }
  // The next check's H becomes the reference: the energy function changed (E, nu, the
  // model, gravity) or something did work the watchdog cannot count (a moving plane).
  void rebase() { have_min_ = false; }
  double scale() const { return scale_; }
  // The machine epsilon of the run's numbers (float or double): an element's J within the
  // determinant's rounding in it counts as collapsed (element_volume_ok), as on the device.
  void set_precision(double eps) { eps_ = eps; }
  // Whether body-body or self-contact runs: an energy rise then names its known source
  // first (README limits, "Energy from body contact").
  void set_body_contact(bool on) { body_contact_ = on; }

  // Checks state s (with its diagnostics d, and W = work the external forces have done
  // so far); nothing when healthy. unstable_dt: the step is above dt_cr, which then is the
  // likely cause. speed: the node speed test (step_health.h). dev: what the backend's own
  // kernels found (Solver::take_health); where they checked (the GPU, at every step and
  // on s), their findings stand in for the host's scans of s for NaN/Inf, inverted
  // elements and speed, and only the energy test runs here.
  struct SpeedTest {
    const std::vector<double>* mass = nullptr;  // nnode [kg]
    double dt = 0;
    double node_energy_max = 0;  // [J]; infinite: no test
  };
  // models: each body's MaterialModel (the inversion test is the Taylor model's), or one
  // for every body.
  std::optional<WatchdogFinding> check(const TetMesh& m, const HostState& s, const Diagnostics& d, double work,
                                       const std::vector<int>& models, bool unstable_dt, const SpeedTest& speed,
                                       const StepHealth& dev);

 private:
  // The host's scans of s (where the backend checked nothing itself).
  std::optional<WatchdogFinding> scan(const TetMesh& m, const HostState& s, const std::vector<int>& models,
                                      bool unstable_dt, const SpeedTest& speed) const;
  double h_min_ = 0, scale_ = 0;
  double eps_ = std::numeric_limits<double>::epsilon();  // the run's precision (set_precision)
  bool have_min_ = false;
  bool body_contact_ = false;
};

// Energy scale of a scene at rest: the initial kinetic energy plus what gravity could
// release over the body's size plus its height above the lowest plane; at least 1 nJ.
double watchdog_energy_scale(const TetMesh& m, const std::vector<double>& mass, const PhysicsParams& p, double ke0);

// "watchdog stopped the run at t = ...: <problem>; dt = ... Likely cause: ... State rolled
// back to t = ..."
// The likelier cause of a blow-up where an obstacle moves at half the softest body's wave
// speed c or faster: what it strikes is crushed within a few steps, which the watchdog then
// finds as NaN, an inverted element or a too-fast node. "obstacle[i] moves at ...; or "
// for the fastest such obstacle, else empty.
std::string fast_obstacle_cause(const std::vector<ObstacleSpec>& obstacles, double c);

// Stiffness-proportional damping (damping.beta) takes the element forces at u + beta v
// (central_difference.h, rayleigh_displacement): f(u) + beta K v only while beta |v| is
// small against the elements. Where beta times the scene's speed v reaches half the
// smallest element altitude le_min, elements at u + beta v fold over at an impact (a 6 mm
// box at 5 m/s blew up at beta = 6e-4 s, beta v / le = 1.7, and ran at 3e-4 s, 0.87):
// "damping.beta = ... below B s" then, else empty. The start and a live change warn at the
// same ratio (Simulation::stiffness_damping_warning).
constexpr double kDampingStrainMax = 0.5;
std::string stiffness_damping_cause(double beta, double v, double le_min);

std::string watchdog_message(const WatchdogFinding& f, double t_bad, double t_back, double dt, double dt_cr);

}  // namespace softtled
